"""The task inspector: a local web page of a task's stage tree, solutions and failures.

``url = task.introspection().serve(port=0)`` (or :func:`serve`) starts an HTTP server on
``127.0.0.1`` in a background thread and returns the page's address at once;
``introspection.stop()`` (:func:`stop`) ends it. ``python -m mtc.inspect saved.json`` serves a
file written by ``Introspection.save`` until Ctrl-C.

The page shows the stage tree with each stage's interface arrows (semantics §1.8 symbols),
solution count, failure count and compute time. Clicking a stage lists its solutions and
failures, cheapest first, a page at a time; selecting one plays it in the embedded viewer
(a :class:`mtc.viewer.Viewer` the inspector starts on localhost, shown in an iframe).

The page loads the tree first and everything else on demand, so a task with thousands of
solutions opens as quickly as a small one. Endpoints (all JSON except ``/``)::

    /                                  the page
    /api/tree[?refresh=1]              task name and stages (no solution lists)
    /api/stage/<id>?kind=solutions|failures&offset=0&limit=100
                                       one page of a stage's solutions or failures by cost
    /api/solution/<id>                 a solution's parts (stage, cost, comment, duration)
    /api/play/<id>                     play the solution in the viewer (POST or GET)
    /api/viewer                        the viewer's state and address
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import re
import sys
import threading
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any
from urllib.parse import parse_qs, urlparse

import numpy as np

from mtc import msgs
from mtc.core import introspection_io
from mtc.core.introspection_io import IntrospectionData
from mtc.core.stage import READS_END, READS_START, WRITES_NEXT_START, WRITES_PREV_END

log = logging.getLogger(__name__)

__all__ = ["Inspector", "serve", "stop", "interface_arrows", "main"]

#: Largest page of a solution or failure list the server hands out.
MAX_PAGE = 1000
_DEFAULT_PAGE = 100


def interface_arrows(flags: int) -> tuple[str, str]:
    """The (start, end) flow symbols of interface flags, as printState writes them (§1.8).

    Start: READS_START "→", WRITES_PREV_END "←", both "↔", none "?".
    End: READS_END "←", WRITES_NEXT_START "→", both "↔", none "?".
    """
    flags = int(flags)
    reads, writes = bool(flags & READS_START), bool(flags & WRITES_PREV_END)
    start = "↔" if reads and writes else "→" if reads else "←" if writes else "?"
    reads, writes = bool(flags & READS_END), bool(flags & WRITES_NEXT_START)
    end = "↔" if reads and writes else "←" if reads else "→" if writes else "?"
    return start, end


def _cost_out(c: float):
    if isinstance(c, float) and not math.isfinite(c):
        return "nan" if c != c else ("inf" if c > 0 else "-inf")
    return c


def _cost_key(info: dict) -> tuple:
    c = info.get("cost", 0.0)
    nan = c != c
    return (nan, 0.0 if nan else c, info.get("id", 0))


def _bundled_model(name: str):
    """The bundled robot (``mtc.robots.<name>()``) of a saved file, or None."""
    import mtc.robots

    factory = getattr(mtc.robots, name, None) if re.fullmatch(r"[a-z][a-z0-9_]*", name or "") else None
    if not callable(factory) or name not in getattr(mtc.robots, "__all__", ()):
        return None
    return factory()


def _stage_or_none(data: IntrospectionData, stage_id) -> dict:
    """The stage entry of an id, or an empty entry (a solution may come without a creator)."""
    try:
        return data.stage(stage_id)
    except KeyError:
        return {}


def _data_of(introspection) -> IntrospectionData:
    """The inspector data of an ``Introspection`` (a fresh snapshot for a live task)."""
    if isinstance(introspection, IntrospectionData):
        return introspection
    task = getattr(introspection, "_task", None)
    if task is not None:
        return IntrospectionData.from_dict(introspection_io.snapshot(task, introspection))
    data = getattr(introspection, "data", None)
    if callable(data):
        data = data()
    if isinstance(data, IntrospectionData):
        return data
    if hasattr(introspection, "to_dict"):
        return IntrospectionData.from_dict(introspection.to_dict())
    raise TypeError(f"cannot inspect a {type(introspection).__name__}: expected an mtc Introspection or IntrospectionData")


class Inspector:
    """The inspector server of one introspection (live task or loaded file).

    Args:
        introspection: An ``mtc.Introspection`` (of a task or loaded) or an
            ``IntrospectionData``.
        robot_model: The robot to draw in the viewer (default: the task's, or for a saved
            file the bundled robot of the file's robot name, e.g. ``panda``).
        port: TCP port on 127.0.0.1 (0: any free port).
        viewer: Start the embedded viewer (False: the page shows the tree and lists only).

    Raises:
        OSError: The port is taken.
    """

    def __init__(self, introspection, robot_model=None, port: int = 0, viewer: bool = True):
        if not isinstance(port, int) or isinstance(port, bool) or not 0 <= port <= 65535:
            raise ValueError(f"port must be an integer in 0..65535 (0: any free port), got {port!r}")
        self._source = introspection
        self._lock = threading.RLock()  # data and viewer are shared by the request threads
        self._data = _data_of(introspection)
        self._sorted: dict[tuple[int, str], list[dict]] = {}
        self._model = robot_model if robot_model is not None else self._find_model()
        self._viewer = None
        self._viewer_state = {"status": "off", "url": None, "reason": "no viewer requested"}
        self._httpd = ThreadingHTTPServer(("127.0.0.1", port), _Handler)
        self._httpd.daemon_threads = True
        self._httpd.inspector = self  # type: ignore[attr-defined]
        self._thread = threading.Thread(target=self._httpd.serve_forever, name="mtc-inspector", daemon=True)
        self._thread.start()
        if viewer:
            self._start_viewer()
        log.info("inspector at %s", self.url)

    # ------------------------------------------------------------------ public
    @property
    def url(self) -> str:
        """The page's address (``http://127.0.0.1:<port>/``)."""
        return f"http://127.0.0.1:{self._httpd.server_address[1]}/"

    @property
    def data(self) -> IntrospectionData:
        """The data shown (the snapshot taken at start or at the page's last refresh)."""
        return self._data

    def stop(self) -> None:
        """Stop the server and the viewer it started. Idempotent."""
        httpd = self._httpd
        if self._thread.is_alive():
            httpd.shutdown()
            self._thread.join(5.0)
        httpd.server_close()
        with self._lock:
            if self._viewer is not None:
                self._viewer.close()
                self._viewer = None
            self._viewer_state = {"status": "off", "url": None, "reason": "the inspector stopped"}

    def refresh(self) -> None:
        """Take a new snapshot of a live task (a loaded file does not change)."""
        if getattr(self._source, "_task", None) is None:
            return
        with self._lock:
            self._data = _data_of(self._source)
            self._sorted.clear()

    # ------------------------------------------------------------------ JSON answers
    def tree(self) -> dict[str, Any]:
        """Task name and stages with arrows and counts (no solution lists)."""
        data = self._data
        stages = []
        for st in data.stages:
            start, end = interface_arrows(st.get("flags", 0))
            stages.append(
                {
                    "id": st["id"],
                    "parent_id": st.get("parent_id", 0),
                    "name": st["name"],
                    "depth": st.get("depth", 0),
                    "flags": st.get("flags", 0),
                    "arrows": [start, end],
                    "num_solutions": st.get("num_solutions", len(st["solutions"])),
                    "num_failures": st.get("num_failures", len(st["failures"])),
                    "stored_failures": len(st["failures"]),
                    "note": st.get("note", ""),
                    "total_compute_time": st.get("total_compute_time", 0.0),
                }
            )
        return {"task": data.task, "stages": stages, "live": getattr(self._source, "_task", None) is not None}

    def stage_list(self, stage_id: int, kind: str, offset: int = 0, limit: int = _DEFAULT_PAGE) -> dict[str, Any]:
        """One page of a stage's solutions or failures, by cost (then id)."""
        if kind not in ("solutions", "failures"):
            raise ValueError(f"kind must be 'solutions' or 'failures', got {kind!r}")
        if offset < 0 or not 1 <= limit <= MAX_PAGE:
            raise ValueError(f"offset must be >= 0 and limit in 1..{MAX_PAGE}, got offset={offset}, limit={limit}")
        with self._lock:
            key = (stage_id, kind)
            items = self._sorted.get(key)
            if items is None:
                items = self._sorted[key] = sorted(self._data.stage(stage_id)[kind], key=_cost_key)
        page = items[offset : offset + limit]
        return {
            "stage_id": stage_id,
            "kind": kind,
            "total": len(items),
            "offset": offset,
            "items": [{"id": i["id"], "cost": _cost_out(i["cost"]), "comment": i.get("comment", "")} for i in page],
        }

    def solution_info(self, solution_id: int) -> dict[str, Any]:
        """A solution's parts in execution order, with their stage, cost and duration."""
        data = self._data
        sol = data.solution(solution_id)
        parts = []
        total = 0.0
        for leaf in data.leaves(solution_id):
            traj = data.trajectory(leaf["id"])
            duration = float(traj["times"][-1]) if traj is not None and len(traj["times"]) else 0.0
            total += duration
            stage = _stage_or_none(data, leaf.get("stage_id"))
            parts.append(
                {
                    "id": leaf["id"],
                    "stage": stage.get("name", ""),
                    "cost": _cost_out(leaf["cost"]),
                    "comment": leaf.get("comment", ""),
                    "duration": duration,
                    "waypoints": 0 if traj is None else len(traj["times"]),
                }
            )
        creator = _stage_or_none(data, sol.get("stage_id"))
        return {
            "id": solution_id,
            "stage": creator.get("name", ""),
            "cost": _cost_out(sol["cost"]),
            "comment": sol.get("comment", ""),
            "duration": total,
            "parts": parts,
        }

    def viewer_state(self) -> dict[str, Any]:
        with self._lock:
            return dict(self._viewer_state)

    def play(self, solution_id: int) -> dict[str, Any]:
        """Play a solution in the viewer; returns its duration [s] (0: a scene shown)."""
        with self._lock:
            viewer = self._viewer
            if viewer is None:
                raise RuntimeError(f"no viewer: {self._viewer_state['reason']}")
            segments = self.segments(solution_id)
            duration = viewer.play_segments(segments) if segments else 0.0
            if duration == 0.0 and segments:
                # no motion (e.g. a failed generator state): show the scene it ends in
                last = segments[-1]
                scene = last.end_scene if last.end_scene is not None else last.start_scene
                if scene is not None:
                    viewer.show_scene(scene)
            # the parts' markers (grasp frames, motion arrows, an end effector at an IK target),
            # each in the scene its part ends in
            leaves = self._data.leaves(solution_id)
            markers = viewer.show_markers([
                (marker, seg.end_scene if seg.end_scene is not None else seg.start_scene)
                for leaf, seg in zip(leaves, segments) for marker in leaf.get("markers", ())])
            return {"id": solution_id, "duration": duration, "segments": len(segments), "markers": markers}

    # ------------------------------------------------------------------ playback
    def segments(self, solution_id: int) -> list:
        """The viewer segments of a solution, rebuilt from the data (one per part)."""
        from mtc.scene.robot_trajectory import RobotTrajectory
        from mtc.viewer import Segment

        if self._model is None:
            raise RuntimeError("no robot model to rebuild the solution's scenes with")
        data = self._data
        scenes: dict[int, Any] = {}

        def scene(index):
            if index is None:
                return None
            if index not in scenes:
                scenes[index] = self._scene(index)
            return scenes[index]

        out = []
        for leaf in data.leaves(solution_id):
            start, end = scene(leaf.get("start")), scene(leaf.get("end"))
            traj = data.trajectory(leaf["id"])
            rt = None
            if traj is not None and len(traj["times"]):
                reference = start.current_state if start is not None else end.current_state if end is not None else None
                rt = self._trajectory(RobotTrajectory, traj, reference, leaf["id"])
            out.append(Segment(rt, start, end))
        return out

    def _trajectory(self, cls, traj: dict, reference, solution_id: int):
        from mtc.scene.robot_state import RobotState

        model = self._model
        group = model.get_joint_model_group(traj["group"])
        names = list(group.variable_names)
        positions = np.asarray(traj["positions"], dtype=float).reshape(len(traj["times"]), -1)
        if traj["joint_names"] != names:
            # columns by name: a file may list the group's joints in another order
            missing = [n for n in names if n not in traj["joint_names"]]
            if missing:
                raise ValueError(f"solution {solution_id}: trajectory lacks joints {missing} of group {traj['group']!r}")
            positions = positions[:, [traj["joint_names"].index(n) for n in names]]
        if reference is None:
            reference = RobotState(model)
        return cls.from_positions(model, traj["group"], reference, positions, np.asarray(traj["times"], dtype=float))

    def _scene(self, index: int):
        """A stored scene as a PlanningScene of the inspector's robot."""
        from mtc.scene.planning_scene import PlanningScene
        from mtc.scene.robot_state import RobotState

        model = self._model
        msg = self._data.scene_msg(index)
        scene = PlanningScene(model, msg.name)
        names = list(msg.robot_state.joint_state.name)
        q = RobotState(model).positions.copy()
        variables = list(model.variable_names)
        for name, value in zip(names, msg.robot_state.joint_state.position):
            if name in variables:
                q[variables.index(name)] = value
        scene.current_state = RobotState(model, q)
        for obj in msg.world.collision_objects:
            obj.operation = msgs.CollisionObject.ADD
            scene.apply_collision_object(obj)
        for att in msg.robot_state.attached_collision_objects:
            att.object.operation = msgs.CollisionObject.ADD
            scene.apply_attached_collision_object(att)
        return scene

    # ------------------------------------------------------------------ internals
    def _find_model(self):
        task = getattr(self._source, "_task", None)
        if task is not None:
            return task.getRobotModel()
        names = list(self._data.robots)
        if len(names) == 1:
            return _bundled_model(names[0])
        return None

    def _start_viewer(self) -> None:
        if self._model is None:
            robots = ", ".join(repr(n) for n in self._data.robots) or "none"
            self._viewer_state = {
                "status": "unavailable",
                "url": None,
                "reason": f"no robot model to draw (the data's robots: {robots}); pass robot_model= or --urdf/--srdf",
            }
            return
        self._viewer_state = {"status": "starting", "url": None, "reason": "the viewer is starting"}
        # the viewer takes a second or two to start: the page paints the tree meanwhile
        threading.Thread(target=self._open_viewer, name="mtc-inspector-viewer", daemon=True).start()

    def _open_viewer(self) -> None:
        from mtc.viewer import Viewer

        try:
            viewer = Viewer(self._model)
        except Exception as e:  # the page says why; the tree and lists still work
            log.warning("inspector: the viewer did not start: %s", e)
            with self._lock:
                self._viewer_state = {"status": "unavailable", "url": None, "reason": f"the viewer did not start: {e}"}
            return
        with self._lock:
            if self._viewer_state["status"] != "starting":  # stopped meanwhile
                viewer.close()
                return
            if viewer.url is None:
                self._viewer_state = {
                    "status": "unavailable",
                    "url": None,
                    "reason": "the viewer is disabled (MTC_NO_VIEWER is set)",
                }
                return
            self._viewer = viewer
            self._viewer_state = {"status": "ready", "url": viewer.url, "reason": ""}


class _Handler(BaseHTTPRequestHandler):
    server_version = "mtc-inspector"

    def log_message(self, format, *args):  # noqa: A002 - the base class's name
        log.debug("inspector: " + format, *args)

    def do_GET(self):
        self._route()

    def do_POST(self):
        self._route()

    def _send(self, status: int, body: bytes, ctype: str) -> None:
        self.send_response(status)
        self.send_header("Content-Type", ctype)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        self.wfile.write(body)

    def _json(self, obj: Any, status: int = 200) -> None:
        self._send(status, json.dumps(obj, allow_nan=False, separators=(",", ":")).encode(), "application/json")

    def _route(self) -> None:
        inspector: Inspector = self.server.inspector  # type: ignore[attr-defined]
        url = urlparse(self.path)
        query = {k: v[-1] for k, v in parse_qs(url.query).items()}
        parts = [p for p in url.path.split("/") if p]
        try:
            if not parts or parts == ["index.html"]:
                self._send(200, PAGE.encode(), "text/html; charset=utf-8")
            elif parts == ["api", "tree"]:
                if query.get("refresh") == "1":
                    inspector.refresh()
                self._json(inspector.tree())
            elif len(parts) == 3 and parts[:2] == ["api", "stage"]:
                self._json(
                    inspector.stage_list(
                        _int(parts[2], "stage id"),
                        query.get("kind", "solutions"),
                        _int(query.get("offset", "0"), "offset"),
                        _int(query.get("limit", str(_DEFAULT_PAGE)), "limit"),
                    )
                )
            elif len(parts) == 3 and parts[:2] == ["api", "solution"]:
                self._json(inspector.solution_info(_int(parts[2], "solution id")))
            elif len(parts) == 3 and parts[:2] == ["api", "play"]:
                self._json(inspector.play(_int(parts[2], "solution id")))
            elif parts == ["api", "viewer"]:
                self._json(inspector.viewer_state())
            else:
                self._json({"error": f"no such page: {url.path}"}, HTTPStatus.NOT_FOUND)
        except (KeyError, ValueError) as e:
            self._json({"error": msgs.error_text(e)}, HTTPStatus.NOT_FOUND if isinstance(e, KeyError) else 400)
        except RuntimeError as e:
            self._json({"error": str(e)}, HTTPStatus.CONFLICT)
        except (BrokenPipeError, ConnectionResetError):
            pass  # the page went away mid-answer
        except Exception as e:  # a bug must show on the page, not kill the request silently
            log.exception("inspector: %s failed", self.path)
            self._json({"error": f"{type(e).__name__}: {e}"}, HTTPStatus.INTERNAL_SERVER_ERROR)


def _int(text: str, what: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise ValueError(f"{what} must be an integer, got {text!r}") from None


# ---------------------------------------------------------------------------- functions
def serve(introspection, port: int = 0, robot_model=None, viewer: bool = True) -> str:
    """Serve the inspector page of ``introspection`` (what ``Introspection.serve`` does).

    Starts (or restarts) the server in a background thread and returns at once.

    Args:
        introspection: ``task.introspection()`` or ``Introspection.load(path)``.
        port: TCP port on 127.0.0.1 (0: any free port).
        robot_model: The robot for the viewer (default: the task's / the file's bundled robot).
        viewer: Start the embedded viewer.

    Returns:
        The page's address, ``http://127.0.0.1:<port>/``.
    """
    stop(introspection)
    inspector = Inspector(introspection, robot_model=robot_model, port=port, viewer=viewer)
    introspection._inspector = inspector
    return inspector.url


def stop(introspection) -> None:
    """Stop the inspector that :func:`serve` started for ``introspection`` (if any)."""
    inspector = getattr(introspection, "_inspector", None)
    if inspector is not None:
        inspector.stop()
        introspection._inspector = None


def main(argv: list[str] | None = None) -> int:
    """``python -m mtc.inspect saved.json [--port N]``: serve a saved task until Ctrl-C."""
    parser = argparse.ArgumentParser(
        prog="python -m mtc.inspect",
        description="Serve the task inspector page of a saved introspection file "
        "(written by task.introspection().save(path)) on 127.0.0.1 until Ctrl-C.",
    )
    parser.add_argument("file", nargs="?", help="introspection JSON file")
    parser.add_argument("--port", type=int, default=0, help="TCP port on 127.0.0.1 (default: any free port)")
    parser.add_argument("--urdf", help="robot description for the viewer (default: the bundled robot the file names)")
    parser.add_argument("--srdf", help="semantic description that goes with --urdf")
    parser.add_argument("--no-viewer", action="store_true", help="do not start the embedded viewer")
    args = parser.parse_args(argv)
    if args.file is None:
        parser.print_usage(sys.stderr)
        sys.stderr.write(
            "\nGive the file to inspect. Write one from a script with\n"
            "    task.introspection().save('task.json')\n"
            "or serve a live task directly with\n"
            "    url = task.introspection().serve(port=0)\n"
        )
        return 2
    if args.srdf and not args.urdf:
        parser.error("--srdf needs --urdf")
    try:
        data = introspection_io.load(args.file)
    except (OSError, ValueError) as e:
        sys.stderr.write(f"python -m mtc.inspect: {e}\n")
        return 1
    model = None
    if args.urdf:
        from mtc.scene.robot_model import RobotModel

        model = RobotModel(args.urdf, args.srdf) if args.srdf else RobotModel(args.urdf)
    try:
        inspector = Inspector(data, robot_model=model, port=args.port, viewer=not args.no_viewer)
    except OSError as e:
        sys.stderr.write(f"python -m mtc.inspect: cannot listen on 127.0.0.1:{args.port}: {e}\n")
        return 1
    print(f"inspector at {inspector.url}  (Ctrl-C to stop)", flush=True)
    try:
        threading.Event().wait()
    except KeyboardInterrupt:
        pass
    finally:
        inspector.stop()
    return 0


PAGE = r"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>mtc inspector</title>
<style>
  body { margin: 0; font: 13px system-ui, sans-serif; display: grid; height: 100vh;
         grid-template-columns: minmax(420px, 45%) 1fr; grid-template-rows: auto 1fr 55%; }
  header { grid-column: 1 / 3; padding: 6px 10px; background: #2d3e50; color: #fff; display: flex; gap: 12px; align-items: center; }
  header h1 { font-size: 15px; margin: 0; }
  #tree-pane { grid-row: 2 / 4; overflow: auto; border-right: 1px solid #ccc; }
  #list-pane { overflow: auto; border-bottom: 1px solid #ccc; }
  #viewer-pane { position: relative; }
  #viewer-pane iframe { width: 100%; height: 100%; border: 0; }
  #viewer-msg { position: absolute; top: 8px; left: 8px; color: #555; }
  table { border-collapse: collapse; width: 100%; }
  th, td { padding: 2px 6px; text-align: right; white-space: nowrap; }
  th { position: sticky; top: 0; background: #eee; }
  td.name, th.name { text-align: left; }
  td.comment { text-align: left; white-space: normal; }
  td.arrow { text-align: center; font-size: 16px; }
  tr.stage { cursor: pointer; }
  tr.stage:hover, tr.item:hover { background: #eef4ff; }
  tr.selected { background: #cfe0ff !important; }
  tr.item { cursor: pointer; }
  tr.failed td { color: #a33; }
  .tabs button { margin-right: 4px; }
  .tabs button.on { font-weight: bold; }
  #list-head { padding: 4px 8px; display: flex; gap: 10px; align-items: center; }
  button.more { margin: 6px; }
  #parts-head { padding: 8px 8px 2px; color: #333; }
</style>
</head>
<body>
<header><h1 id="title">mtc inspector</h1><span id="summary"></span>
  <button id="refresh" hidden>refresh</button><span id="status"></span></header>
<div id="tree-pane"><table id="tree"><thead><tr><th class="name">stage</th><th title="start interface">in</th>
  <th>solutions</th><th title="end interface">out</th><th>failures</th><th>time [s]</th></tr></thead><tbody></tbody></table></div>
<div id="list-pane"><div id="list-head"><b id="list-title">select a stage</b>
  <span class="tabs"><button id="tab-solutions" class="on">solutions</button><button id="tab-failures">failures</button></span>
  <span id="list-count"></span></div>
  <table id="list"><thead><tr><th>id</th><th>cost</th><th class="name">comment</th></tr></thead><tbody></tbody></table>
  <button class="more" id="more" hidden>more</button>
  <div id="parts-head"></div>
  <table id="parts" hidden><thead><tr><th>part</th><th class="name">stage</th><th>cost</th><th>duration [s]</th>
    <th class="name">comment</th></tr></thead><tbody></tbody></table></div>
<div id="viewer-pane"><span id="viewer-msg">viewer: starting</span><iframe id="viewer" title="viewer"></iframe></div>
<script>
"use strict";
const PAGE = 100;
// state the tests (and curious users) can read: window.inspector
const inspector = window.inspector = { treeLoaded: false, treePaintedAt: null, stage: null, kind: "solutions",
  listed: 0, total: 0, selected: null, playing: null, duration: null, viewer: null, error: null };
const $ = (id) => document.getElementById(id);
function fmtCost(c) { return typeof c === "number" ? (Math.round(c * 1e4) / 1e4).toString() : String(c); }
function setStatus(text) { $("status").textContent = text; }
async function getJSON(url, opts) {
  const r = await fetch(url, opts);
  const body = await r.json();
  if (!r.ok) throw new Error(body.error || r.statusText);
  return body;
}
function cell(row, text, cls) { const td = row.insertCell(); td.textContent = text; if (cls) td.className = cls; return td; }

async function loadTree(refresh) {
  const t = await getJSON("/api/tree" + (refresh ? "?refresh=1" : ""));
  $("title").textContent = "mtc inspector: " + (t.task.name || "task");
  $("summary").textContent = (t.task.num_solutions ?? "?") + " solution(s)";
  $("refresh").hidden = !t.live;
  const body = $("tree").tBodies[0];
  body.replaceChildren();
  for (const s of t.stages) {
    const row = body.insertRow();
    row.className = "stage"; row.dataset.id = s.id;
    const name = cell(row, s.name, "name"); name.style.paddingLeft = (6 + 16 * s.depth) + "px";
    cell(row, s.arrows[0], "arrow");
    cell(row, s.num_solutions, "nsol");
    cell(row, s.arrows[1], "arrow");
    const nfail = cell(row, s.num_failures, "nfail");
    if (s.note) nfail.title = s.note;
    cell(row, s.total_compute_time.toFixed(4), "time");
    row.onclick = () => selectStage(s);
  }
  inspector.stages = t.stages;
  inspector.treeLoaded = true;
  // the frame after the rows went in is the tree's first paint
  requestAnimationFrame(() => { inspector.treePaintedAt = inspector.treePaintedAt || performance.now(); });
  if (inspector.stage) {
    const s = t.stages.find((x) => x.id === inspector.stage.id);
    if (s) selectStage(s, inspector.kind);
  }
}

function markSelected(tbody, attr, value) {
  for (const r of tbody.rows) r.classList.toggle("selected", r.dataset[attr] === String(value));
}

async function selectStage(s, kind) {
  inspector.stage = s; inspector.kind = kind || inspector.kind;
  markSelected($("tree").tBodies[0], "id", s.id);
  $("tab-solutions").classList.toggle("on", inspector.kind === "solutions");
  $("tab-failures").classList.toggle("on", inspector.kind === "failures");
  $("list-title").textContent = s.note ? `${s.name}: ${s.note}` : s.name;
  $("list").tBodies[0].replaceChildren();
  inspector.listed = 0;
  await loadMore();
}

async function loadMore() {
  const s = inspector.stage, kind = inspector.kind;
  const r = await getJSON(`/api/stage/${s.id}?kind=${kind}&offset=${inspector.listed}&limit=${PAGE}`);
  if (inspector.stage !== s || inspector.kind !== kind) return;  // another stage was clicked meanwhile
  const body = $("list").tBodies[0];
  for (const item of r.items) {
    const row = body.insertRow();
    row.className = "item" + (kind === "failures" ? " failed" : ""); row.dataset.id = item.id;
    cell(row, item.id); cell(row, fmtCost(item.cost)); cell(row, item.comment, "comment");
    row.onclick = () => selectSolution(item.id);
  }
  inspector.listed += r.items.length; inspector.total = r.total;
  $("list-count").textContent = `${inspector.listed} of ${r.total} ${kind}, cheapest first`;
  $("more").hidden = inspector.listed >= r.total;
}

async function selectSolution(id) {
  inspector.selected = id;
  markSelected($("list").tBodies[0], "id", id);
  try {
    const info = await getJSON(`/api/solution/${id}`);
    setStatus(`solution ${id}: ${info.parts.length} part(s), ${info.duration.toFixed(2)} s`);
    showParts(info);
    const r = await getJSON(`/api/play/${id}`, { method: "POST" });
    inspector.playing = id; inspector.duration = r.duration; inspector.error = null;
  } catch (e) {
    inspector.error = String(e.message || e); setStatus("solution " + id + ": " + inspector.error);
  }
}

function showParts(info) {
  $("parts-head").textContent = `solution ${info.id} of stage ${info.stage}: cost ${fmtCost(info.cost)}` +
    (info.comment ? `, ${info.comment}` : "") + `; its parts in order:`;
  const body = $("parts").tBodies[0];
  body.replaceChildren();
  for (const p of info.parts) {
    const row = body.insertRow();
    cell(row, p.id); cell(row, p.stage, "name"); cell(row, fmtCost(p.cost)); cell(row, p.duration.toFixed(3));
    cell(row, p.comment, "comment");
  }
  $("parts").hidden = false;
}

async function pollViewer() {
  let v;
  try { v = await getJSON("/api/viewer"); } catch (e) { v = { status: "unavailable", reason: String(e) }; }
  inspector.viewer = v.status;
  if (v.status === "ready") {
    if ($("viewer").src !== v.url) $("viewer").src = v.url;
    $("viewer-msg").textContent = "";
  } else {
    $("viewer-msg").textContent = "viewer: " + (v.reason || v.status);
    if (v.status === "starting") setTimeout(pollViewer, 300);
  }
}

$("tab-solutions").onclick = () => inspector.stage && selectStage(inspector.stage, "solutions");
$("tab-failures").onclick = () => inspector.stage && selectStage(inspector.stage, "failures");
$("more").onclick = loadMore;
$("refresh").onclick = () => loadTree(true);
loadTree(false).catch((e) => { inspector.error = String(e); setStatus("cannot load the tree: " + e); });
pollViewer();
</script>
</body>
</html>
"""


if __name__ == "__main__":
    sys.exit(main())
