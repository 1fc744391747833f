"""The task inspector (mtc.inspect): its JSON endpoints, playback data, the command line, and
the page in a real headless Chromium (Debian's chromium + chromedriver through selenium).

The browser tests need ``/usr/bin/chromium``, ``/usr/bin/chromedriver`` and ``selenium``
(.ci/run installs them). Where they are missing they are skipped, except under CI (``CI``
set), where that is a failure. Screenshots go to pytest's temporary directory, never into
the repository.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import numpy as np
import pytest

import mtc
from mtc import core
from mtc import inspect as mi
from mtc.core import introspection_io
from mtc.core import stage as st
from mtc.viewer import render_frames

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "bench"))
sys.path.insert(0, str(HERE.parent / "examples"))
import mockups  # noqa: E402

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"


# ----------------------------------------------------------------------------- helpers
def get(url: str, method: str = "GET"):
    with urllib.request.urlopen(urllib.request.Request(url, method=method), timeout=30) as r:
        return json.loads(r.read())


def get_error(url: str) -> tuple[int, str]:
    with pytest.raises(urllib.error.HTTPError) as info:
        urllib.request.urlopen(url, timeout=30)
    return info.value.code, json.loads(info.value.read())["error"]


def stage_rows(task) -> list[tuple[str, int, int]]:
    """(name, solutions, failures) of every stage in tree order, from the task itself."""
    rows = []

    def visit(stage, depth):
        rows.append((stage.name, len(stage.solutions), stage.numFailures()))
        return True

    task.stages.traverseRecursively(visit)
    return rows


def wait_for(predicate, timeout: float, what: str, interval: float = 0.05):
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(interval)


@pytest.fixture(scope="module")
def pickplace_task():
    """The pick-and-place example, planned (its solutions carry attach/detach scenes)."""
    import pickplace

    mtc.reset_current_scene()
    task = pickplace.make_task()
    assert task.plan(max_solutions=4)
    yield task
    mtc.reset_current_scene()


def many_solutions_task(solutions: int, failures: int):
    """The inspector benchmark's task: S successes and F failures with trajectories."""
    from inspector_bench import TrajectoryPropagator

    mockups.resetMockupIds()
    task = core.Task()
    task.setRobotModel(mockups.toy_model())
    task.add(mockups.GeneratorMockup([float(i % 7) for i in range(solutions + failures)]))
    task.add(TrajectoryPropagator(period=failures // solutions + 1, waypoints=10))
    assert task.plan()
    assert task.numSolutions() == solutions and task["move"].numFailures() == failures
    return task


@pytest.fixture
def served():
    """serve() helper that always stops what it started."""
    started = []

    def start(introspection, **kwargs):
        url = mi.serve(introspection, **kwargs)
        started.append(introspection)
        return url

    yield start
    for introspection in started:
        mi.stop(introspection)


# ----------------------------------------------------------------------------- no browser
def test_interface_arrows_are_the_printstate_symbols():
    """§1.8: start READS_START →, WRITES_PREV_END ←, both ↔, none ?; end mirrored."""
    assert mi.interface_arrows(st.GENERATE) == ("←", "→")
    assert mi.interface_arrows(st.PROPAGATE_FORWARDS) == ("→", "→")
    assert mi.interface_arrows(st.PROPAGATE_BACKWARDS) == ("←", "←")
    assert mi.interface_arrows(st.CONNECT) == ("→", "←")
    assert mi.interface_arrows(0) == ("?", "?")
    both = st.READS_START | st.WRITES_PREV_END | st.READS_END | st.WRITES_NEXT_START
    assert mi.interface_arrows(both) == ("↔", "↔")


def test_tree_matches_the_task(pickplace_task, served):
    """/api/tree: every stage in tree order with the task's counts and its printState arrows."""
    task = pickplace_task
    url = served(task.introspection(), viewer=False)
    assert url.startswith("http://127.0.0.1:") and url.endswith("/")
    tree = get(url + "api/tree")
    assert [(s["name"], s["num_solutions"], s["num_failures"]) for s in tree["stages"]] == stage_rows(task)
    assert tree["task"]["num_solutions"] == task.numSolutions()
    lines = [line.split(" / ")[0].split() for line in _print_state(task).splitlines()]
    # printState writes "<sizes> <start arrow> <n> <end arrow> <sizes>": the arrows agree
    assert [tuple(s["arrows"]) for s in tree["stages"]] == [(w[2], w[4]) for w in lines]
    assert all(s["total_compute_time"] >= 0 for s in tree["stages"])
    assert get(url + "api/viewer")["status"] == "off"


def test_loaded_introspection_serves(pickplace_task, tmp_path, monkeypatch):
    """mtc.Introspection.load(path).serve() shows the saved tree; under MTC_NO_VIEWER the
    viewer pane says why it is empty."""
    monkeypatch.setenv("MTC_NO_VIEWER", "1")
    path = tmp_path / "task.json"
    pickplace_task.introspection().save(path)
    loaded = mtc.Introspection.load(path)
    url = loaded.serve(port=0)
    try:
        tree = get(url + "api/tree")
        assert [(s["name"], s["num_solutions"], s["num_failures"]) for s in tree["stages"]] == stage_rows(pickplace_task)
        state = wait_for(lambda: (v := get(url + "api/viewer"))["status"] != "starting" and v, 30, "the viewer")
        assert state["status"] == "unavailable" and "MTC_NO_VIEWER" in state["reason"]
    finally:
        loaded.stop()
    with pytest.raises(urllib.error.URLError):
        urllib.request.urlopen(url + "api/tree", timeout=5)


def _print_state(task) -> str:
    import io

    out = io.StringIO()
    task.printState(out)
    return out.getvalue()


def test_lists_sorted_by_cost_and_paginated(served):
    """A stage's solutions and failures come cheapest first, a page at a time."""
    task = many_solutions_task(20, 60)
    url = served(task.introspection(), viewer=False)
    tree = get(url + "api/tree")
    move = next(s for s in tree["stages"] if s["name"] == "move")
    assert (move["num_solutions"], move["num_failures"]) == (20, 60)
    seen = []
    offset = 0
    while True:
        page = get(url + f"api/stage/{move['id']}?kind=failures&offset={offset}&limit=25")
        assert page["total"] == 60 and len(page["items"]) <= 25
        if not page["items"]:
            break
        seen += page["items"]
        offset += len(page["items"])
    assert len(seen) == 60 and len({i["id"] for i in seen}) == 60
    costs = [i["cost"] for i in seen]
    assert costs == sorted(costs)
    assert all(i["comment"].startswith("state ") for i in seen)
    sols = get(url + f"api/stage/{move['id']}?kind=solutions&limit=1000")
    assert sorted(s.cost for s in task["move"].solutions) == [i["cost"] for i in sols["items"]]
    # a failure's playback data: one part with its trajectory
    info = get(url + f"api/solution/{seen[0]['id']}")
    assert info["comment"] == seen[0]["comment"] and info["parts"][0]["waypoints"] == 10


def test_bad_requests_name_the_problem(pickplace_task, served):
    """Unknown ids and bad parameters answer 404/400 with a message naming the bad value."""
    url = served(pickplace_task.introspection(), viewer=False)
    assert get_error(url + "api/stage/999") == (404, "no stage with id 999 (ids: [" + ", ".join(
        str(s["id"]) for s in get(url + "api/tree")["stages"]) + "])")
    code, text = get_error(url + "api/stage/1?kind=winners")
    assert code == 400 and "kind must be 'solutions' or 'failures'" in text
    code, text = get_error(url + "api/stage/1?limit=0")
    assert code == 400 and "limit in 1..1000" in text
    code, text = get_error(url + "api/solution/abc")
    assert code == 400 and "solution id must be an integer" in text
    assert get_error(url + "api/solution/99999")[0] == 404
    code, text = get_error(url + "api/play/1")
    assert code == 409 and "no viewer" in text
    assert get_error(url + "nowhere")[0] == 404


def test_stop_ends_the_server(pickplace_task):
    """stop() closes the port; calling it again does nothing."""
    introspection = pickplace_task.introspection()
    url = mi.serve(introspection, viewer=False)
    assert get(url + "api/tree")["stages"]
    mi.stop(introspection)
    with pytest.raises(urllib.error.URLError):
        urllib.request.urlopen(url + "api/tree", timeout=5)
    mi.stop(introspection)  # idempotent


def test_playback_segments_rebuild_the_solution(pickplace_task):
    """The segments the viewer plays, rebuilt from the saved data, animate as the live solution
    does: the robot moves, and the box follows the hand only between attach and detach."""
    task = pickplace_task
    introspection = task.introspection()
    inspector = mi.Inspector(introspection, viewer=False)
    try:
        solution = task.solutions[0]
        sid = introspection.solutionId(solution)
        rebuilt = inspector.segments(sid)
        live = [(leaf.trajectory, leaf.start.scene, leaf.end.scene) for leaf in _leaves(solution)]
        assert len(rebuilt) == len(live)
        model = task.getRobotModel()
        duration = sum(float(np.sum(t.get_waypoint_durations())) for t, _, _ in live if t is not None)
        times = np.linspace(0.0, duration, 60)
        a = render_frames(model, rebuilt, times)
        b = render_frames(model, live, times)
        assert sorted(a.paths) == sorted(b.paths)
        for path in b.paths:
            np.testing.assert_allclose(a[path], b[path], atol=1e-9, err_msg=path)
            assert (a.visible[path] == b.visible[path]).all(), path
        hand, box = a["robot/panda_hand"], a["objects/grasp_object"]
        assert np.ptp(hand[:, :3, 3], axis=0).max() > 0.1  # the robot moves
        moved = np.linalg.norm(np.diff(box[:, :3, 3], axis=0), axis=1) > 1e-6
        assert moved.any() and not moved.all()  # carried part of the time, resting otherwise
    finally:
        inspector.stop()


def test_play_draws_the_solution_markers(pickplace_task, monkeypatch):
    """Playing a solution in the inspector's viewer draws the markers of its parts, read back
    from the data (grasp frames, IK targets with the end effector, motion arrows)."""
    monkeypatch.delenv("MTC_NO_VIEWER", raising=False)
    task = pickplace_task
    introspection = task.introspection()
    inspector = mi.Inspector(introspection, viewer=True)
    try:
        deadline = time.monotonic() + 60
        while inspector.viewer_state()["status"] == "starting" and time.monotonic() < deadline:
            time.sleep(0.1)
        assert inspector.viewer_state()["status"] == "ready", inspector.viewer_state()
        solution = task.solutions[0]
        kinds = [m["type"] for leaf in _leaves(solution) for m in leaf.markers]
        assert {"frame", "arrow", "links"} <= set(kinds)
        result = inspector.play(introspection.solutionId(solution))
        assert result["markers"] == len(kinds)
    finally:
        inspector.stop()


def _leaves(solution):
    out = []
    solution._leaves(out)
    return out


def test_saved_file_serves_the_same_tree(pickplace_task, tmp_path, served):
    """Introspection saved to JSON and loaded back serves the same tree, lists and playback."""
    task = pickplace_task
    path = tmp_path / "task.json"
    introspection_io.save(task, path, task.introspection())
    loaded = introspection_io.load(path)
    live_url = served(task.introspection(), viewer=False)
    saved_url = served(loaded, viewer=False)
    live, saved = get(live_url + "api/tree"), get(saved_url + "api/tree")
    assert saved["stages"] == live["stages"] and not saved["live"] and live["live"]
    root = live["stages"][0]["id"]
    assert get(saved_url + f"api/stage/{root}") == get(live_url + f"api/stage/{root}")
    sid = get(saved_url + f"api/stage/{root}")["items"][0]["id"]
    assert get(saved_url + f"api/solution/{sid}") == get(live_url + f"api/solution/{sid}")
    # the file names the bundled robot, so a loaded file can be played too
    assert mi.Inspector(loaded, viewer=False)._model is task.getRobotModel()


def test_a_stage_note_is_served_and_saved(tmp_path, served):
    """A failure MTC leaves without a comment (here: a predicate's bare rejection) and a stage
    that never ran say why in the tree's ``note`` (the list title and failure count's tooltip
    show it), live and from a saved file; a file without notes loads with empty ones."""
    from mtc import stages

    mockups.resetMockupIds()
    task = core.Task()
    task.setRobotModel(mockups.toy_model())
    gen = mockups.GeneratorMockup([1.0])
    task.add(stages.PredicateFilter("filter", gen))
    task["filter"].predicate = lambda s: False
    assert not task.plan()
    live = get(served(task.introspection(), viewer=False) + "api/tree")
    notes = {s["name"]: s["note"] for s in live["stages"]}
    assert notes["filter"] == "rejected by the predicate" and notes[gen.name] == ""
    path = tmp_path / "task.json"
    introspection_io.save(task, path, task.introspection())
    assert get(served(introspection_io.load(path), viewer=False) + "api/tree")["stages"] == live["stages"]
    data = json.loads(path.read_text())
    for stage in data["stages"]:
        del stage["note"]
    path.write_text(json.dumps(data))
    assert all(s["note"] == "" for s in introspection_io.load(path).stages)


def test_command_line_without_file_explains_usage():
    """python -m mtc.inspect without a file prints usage and how to write a file."""
    r = subprocess.run([sys.executable, "-m", "mtc.inspect"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2
    assert "usage: python -m mtc.inspect" in r.stderr and "task.introspection().save" in r.stderr


def test_command_line_rejects_a_bad_file(tmp_path):
    """A JSON file that is no introspection data is refused with the loader's message."""
    bad = tmp_path / "bad.json"
    bad.write_text('{"hello": 1}')
    r = subprocess.run([sys.executable, "-m", "mtc.inspect", str(bad)], capture_output=True, text=True, timeout=60)
    assert r.returncode == 1 and "not mtc introspection data" in r.stderr


def test_command_line_serves_a_saved_file(pickplace_task, tmp_path):
    """python -m mtc.inspect saved.json prints the address and serves the saved tree."""
    path = tmp_path / "task.json"
    introspection_io.save(pickplace_task, path, pickplace_task.introspection())
    proc = subprocess.Popen(
        [sys.executable, "-m", "mtc.inspect", str(path), "--no-viewer"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        line = proc.stdout.readline()
        assert line.startswith("inspector at http://127.0.0.1:"), line + proc.stderr.read()
        url = line.split()[2]
        tree = get(url + "api/tree")
        assert [(s["name"], s["num_solutions"], s["num_failures"]) for s in tree["stages"]] == stage_rows(pickplace_task)
    finally:
        proc.terminate()
        proc.wait(10)


# ----------------------------------------------------------------------------- browser
def _require_browser():
    missing = [p for p in (CHROMIUM, CHROMEDRIVER) if not os.path.exists(p)]
    try:
        import selenium  # noqa: F401
    except ImportError:
        missing.append("selenium (pip)")
    if missing:
        message = f"the browser test needs {', '.join(missing)} (apt: chromium chromium-driver; pip: selenium)"
        if os.environ.get("CI"):
            pytest.fail(message)
        pytest.skip(message)


@pytest.fixture
def browser(tmp_path):
    """Headless Debian Chromium driven by selenium, with a fresh profile."""
    _require_browser()
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in (
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--disable-dev-shm-usage",
        "--enable-unsafe-swiftshader",  # WebGL (the meshcat viewer) on the CPU
        "--window-size=1400,900",
        f"--user-data-dir={tmp_path / 'chromium-profile'}",
    ):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    driver.set_page_load_timeout(60)
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(tmp_path / "chromium-profile", ignore_errors=True)


def js_wait(driver, expression: str, timeout: float, what: str):
    return wait_for(lambda: driver.execute_script(f"return {expression}"), timeout, what)


def test_page_lists_stages_and_plays_a_solution(pickplace_task, browser, tmp_path, monkeypatch):
    """The page lists the pick-and-place stages with the task's counts; selecting a solution
    starts its animation in the embedded meshcat viewer."""
    from selenium.webdriver.common.by import By

    monkeypatch.delenv("MTC_NO_VIEWER", raising=False)  # the page needs a real viewer
    task = pickplace_task
    introspection = task.introspection()
    url = introspection.serve(port=0)
    try:
        browser.get(url)
        js_wait(browser, "window.inspector && window.inspector.treeLoaded", 20, "the stage tree")
        rows = browser.find_elements(By.CSS_SELECTOR, "#tree tbody tr")
        shown = [
            (
                r.find_element(By.CSS_SELECTOR, "td.name").text,
                int(r.find_element(By.CSS_SELECTOR, "td.nsol").text),
                int(r.find_element(By.CSS_SELECTOR, "td.nfail").text),
            )
            for r in rows
        ]
        assert shown == stage_rows(task)
        arrows = [[c.text for c in r.find_elements(By.CSS_SELECTOR, "td.arrow")] for r in rows]
        assert arrows[1] == ["←", "→"]  # "current" generates

        js_wait(browser, "window.inspector.viewer === 'ready'", 60, "the viewer")
        rows[0].click()  # the task's root container: its solutions are the task's
        js_wait(browser, "window.inspector.listed > 0", 20, "the solution list")
        items = browser.find_elements(By.CSS_SELECTOR, "#list tbody tr")
        assert len(items) == task.numSolutions()
        costs = [float(r.find_elements(By.TAG_NAME, "td")[1].text) for r in items]
        assert costs == sorted(costs)
        assert costs[0] == pytest.approx(task.solutions[0].cost, abs=1e-4)

        frame = browser.find_element(By.ID, "viewer")
        browser.switch_to.frame(frame)
        js_wait(browser, "typeof viewer !== 'undefined' && viewer.connection && viewer.connection.readyState === 1",
                30, "the meshcat page to connect")
        browser.switch_to.default_content()
        items[0].click()
        js_wait(browser, "window.inspector.playing !== null || window.inspector.error", 30, "playback")
        assert browser.execute_script("return window.inspector.error") is None
        played = browser.execute_script("return window.inspector.duration")
        assert played > 1.0
        parts = browser.find_elements(By.CSS_SELECTOR, "#parts tbody tr")
        assert len(parts) == len(_leaves(task.solutions[0]))  # the solution's parts, in order

        browser.switch_to.frame(frame)
        # the clip arrived and its clock runs (a 7 s clip may already be over when we look)
        js_wait(browser, "viewer.animator.actions.length > 0 && viewer.animator.time > 0", 30, "the animation to run")
        animated = browser.execute_script("return viewer.animator.actions.map(a => a.getRoot().name)")
        assert "panda_hand" in animated and "grasp_object" in animated
        # the animation moves the hand, and the box from where it is picked to where it is placed
        where = """
            viewer.animator.seek(arguments[0]);
            // positions in the planning frame: meshcat's root node turns z-up into three.js' y-up
            const root = viewer.scene_tree.find(['meshcat']).object;
            const at = (p) => { const o = viewer.scene_tree.find(p.split('/')).object;
                                o.updateWorldMatrix(true, false);
                                return root.worldToLocal(o.getWorldPosition(new o.position.constructor())).toArray(); };
            return [at('meshcat/mtc/robot/panda_hand'), at('meshcat/mtc/objects/grasp_object')];"""
        duration = browser.execute_script("return viewer.animator.duration")
        assert duration == pytest.approx(played, abs=1e-3)
        hand0, box0 = browser.execute_script(where, 0.0)
        hand1, box1 = browser.execute_script(where, duration)
        assert np.linalg.norm(np.subtract(hand1, hand0)) > 0.1
        # the box's world pose in the saved (live) scenes: picked at (0.307, 0, 0.285), placed
        # at (-0.2, -0.6, 0) as the example says
        np.testing.assert_allclose(box0, [0.30702, 0.0, 0.285], atol=0.02)
        np.testing.assert_allclose(box1, [-0.2, -0.6, 0.0], atol=0.02)
        browser.switch_to.default_content()
        shot = tmp_path / "inspector.png"
        assert browser.save_screenshot(str(shot)) and shot.stat().st_size > 1000
        print("screenshot:", shot)
    finally:
        introspection.stop()


def test_page_shows_a_stage_note(browser):
    """A stage's note is the tooltip of its failure count and follows its name above the list."""
    from selenium.webdriver.common.by import By

    from mtc import stages

    mockups.resetMockupIds()
    task = core.Task()
    task.setRobotModel(mockups.toy_model())
    task.add(stages.PredicateFilter("filter", mockups.GeneratorMockup([1.0])))
    task["filter"].predicate = lambda s: False
    assert not task.plan()
    introspection = task.introspection()
    url = mi.serve(introspection, viewer=False)
    try:
        browser.get(url)
        js_wait(browser, "window.inspector && window.inspector.treeLoaded", 20, "the stage tree")
        row = next(r for r in browser.find_elements(By.CSS_SELECTOR, "#tree tbody tr")
                   if r.find_element(By.CSS_SELECTOR, "td.name").text == "filter")
        assert row.find_element(By.CSS_SELECTOR, "td.nfail").get_attribute("title") == "rejected by the predicate"
        row.click()
        js_wait(browser, "document.getElementById('list-title').textContent.includes('rejected')", 20, "the title")
        assert browser.find_element(By.ID, "list-title").text == "filter: rejected by the predicate"
    finally:
        introspection.stop()


def test_first_paint_with_many_solutions(browser):
    """1,000 solutions and 5,000 failures: serve() and the page's tree under 2 s, lists lazy."""
    task = many_solutions_task(1000, 5000)
    introspection = task.introspection()
    start = time.perf_counter()
    url = mi.serve(introspection, viewer=False)
    served_s = time.perf_counter() - start
    browser.get(url)
    js_wait(browser, "window.inspector.treePaintedAt", 20, "the stage tree's first paint")
    total_s = time.perf_counter() - start
    try:
        paint = browser.execute_script("return window.inspector.treePaintedAt")  # [ms] since navigation
        rows = browser.execute_script("return document.querySelectorAll('#tree tbody tr').length")
        assert rows == len(stage_rows(task))
        # nothing but the tree was fetched: the lists load on demand
        fetched = browser.execute_script("return performance.getEntriesByType('resource').map(e => e.name)")
        assert not any("/api/stage/" in f or "/api/solution/" in f for f in fetched)
        print(f"serve {served_s:.3f} s, page painted the tree {total_s:.3f} s after serve(), {paint:.0f} ms after navigation")
        assert total_s < 2.0, f"serve + first paint took {total_s:.2f} s"
        # a list page of the 5,000 failures is quick too
        browser.execute_script("document.querySelectorAll('#tree tbody tr')[2].click()")
        browser.execute_script("document.getElementById('tab-failures').click()")
        js_wait(browser, "window.inspector.kind === 'failures' && window.inspector.listed === 100", 10, "failures page")
        assert browser.execute_script("return window.inspector.total") == 5000
    finally:
        mi.stop(introspection)
