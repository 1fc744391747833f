"""End-to-end task benchmark: the two pick-and-place examples, over several seeds.

For ``examples/pickplace.py`` (MTC's Python tutorial: a box in free space) and
``examples/pick_place_demo.py`` (MTC's C++ demo: a cylinder on a table) this plans the
example's own task with ``plan(max_solutions=10)`` once per seed and reports, per seed and
as the median over the seeds:

* ``init``: ``task.init()`` (the robot model is loaded once per process beforehand);
* ``first``: time from the start of ``plan()`` to the first complete solution;
* ``10 sol``: time until the 10th solution (or until the search ends, marked ``*`` when it
  ends with fewer);
* the best cost and the number of solutions.

A seed sets the ``seed`` property of every ``PipelinePlanner`` (OMPL) and every
``ComputeIK`` (its random IK restarts) in the task; everything else is deterministic.

Then, for one run per example (the first seed), the time split of ``plan()``:

* by stage kind: the time spent inside each kind of stage's compute methods, exclusive of
  nested stages (the grasp generator inside ``ComputeIK`` counts as "pose generators"); what
  is left of ``plan()`` is the engine's own work ("scheduling": queues, solution lifting,
  cost ordering, callbacks);
* by module (cProfile): self time per module, where time inside compiled functions
  (Pinocchio, coal, numpy, OMPL, ruckig) is charged to the Python module that called them.

Usage: python bench/task_bench.py [--seeds 10] [--solutions 10] [--example pickplace|pick_place_demo]
       [--no-profile]
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import runpy
import sys
import statistics
import time
from collections import defaultdict
from pathlib import Path

import mtc
from mtc import core
from mtc.planners.planner_interface import PlannerInterface

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
# the examples import their shared runner (examples/_demo.py) as a script would find it
if str(EXAMPLES) not in sys.path:
    sys.path.insert(0, str(EXAMPLES))
EXAMPLE_NAMES = ("pickplace", "pick_place_demo")


# ---------------------------------------------------------------------------------------------
# tasks and seeds


def load_example(name: str) -> dict:
    """The example's globals (its ``__main__`` block does not run)."""
    return runpy.run_path(str(EXAMPLES / f"{name}.py"), run_name=f"bench_{name}")


def iter_stages(stage):
    """``stage`` and every stage below it."""
    yield stage
    try:
        children = list(stage)
    except TypeError:  # not a container
        children = []
    for child in children:
        yield from iter_stages(child)


def planners_of(stage) -> list[PlannerInterface]:
    """The planners a stage uses (Connect's (group, planner) pairs, a MoveTo's ``planner``)."""
    found = []
    for _group, planner in getattr(stage, "_planners", []) or []:
        found.append(planner)
    props = stage.properties
    if "planner" in props:
        value = props.get("planner", None)
        if isinstance(value, PlannerInterface):
            found.append(value)
    # planners inside a MultiPlanner, or inside Pick/Place's own Cartesian solver
    nested = []
    for planner in found:
        nested.extend(p for p in getattr(planner, "_planners", []) or [] if isinstance(p, PlannerInterface))
    return found + nested


def seed_task(task: core.Task, seed: int) -> tuple[int, int]:
    """Set ``seed`` on every PipelinePlanner and ComputeIK; returns how many of each were set."""
    planners: dict[int, PlannerInterface] = {}
    iks = 0
    for stage in iter_stages(task.stages):
        for planner in planners_of(stage):
            planners[id(planner)] = planner
        if type(stage).__name__ == "ComputeIK":
            stage.properties.set("seed", seed)
            iks += 1
    seeded = 0
    for planner in planners.values():
        if "seed" in planner.properties:
            planner.properties.set("seed", seed)
            seeded += 1
    return seeded, iks


def make_seeded_task(example: dict, seed: int) -> core.Task:
    """A fresh task of the example (on a fresh current scene), seeded."""
    mtc.reset_current_scene()
    task = example["make_task"]()
    seed_task(task, seed)
    return task


# ---------------------------------------------------------------------------------------------
# timing


def run_once(example: dict, seed: int, max_solutions: int) -> dict:
    """Plan the example's task once; returns timing and cost figures."""
    task = make_seeded_task(example, seed)
    start = time.perf_counter()
    task.init()
    init_s = time.perf_counter() - start

    stamps: list[float] = []
    task.addSolutionCallback(lambda solution: None if solution.isFailure else stamps.append(time.perf_counter()))
    start = time.perf_counter()
    result = task.plan(max_solutions=max_solutions)
    total = time.perf_counter() - start
    costs = [solution.cost for solution in task.solutions]
    return {
        "seed": seed,
        "ok": bool(result),
        "init_s": init_s,
        "first_s": stamps[0] - start if stamps else float("nan"),
        "last_s": stamps[max_solutions - 1] - start if len(stamps) >= max_solutions else total,
        "complete": len(stamps) >= max_solutions,
        "total_s": total,
        "solutions": len(costs),
        "best_cost": min(costs) if costs else float("nan"),
        "costs": costs,
    }


def print_runs(name: str, runs: list[dict], max_solutions: int) -> None:
    print(f"\n== {name}: plan(max_solutions={max_solutions}) over {len(runs)} seeds")
    print(f"{'seed':>4} {'init':>7} {'first':>8} {f'{max_solutions} sol':>9} {'#sol':>5} {'best':>8}  costs")
    for r in runs:
        mark = "" if r["complete"] else "*"
        costs = ", ".join(f"{c:.2f}" for c in r["costs"][:max_solutions])
        print(f"{r['seed']:>4} {r['init_s']:7.3f} {r['first_s']:8.3f} {r['last_s']:8.3f}{mark:1} "
              f"{r['solutions']:>5} {r['best_cost']:8.3f}  [{costs}]")

    def median(key):
        values = [r[key] for r in runs if r[key] == r[key]]  # no NaN
        return statistics.median(values) if values else float("nan")

    print(f"{'med':>4} {median('init_s'):7.3f} {median('first_s'):8.3f} {median('last_s'):8.3f}  "
          f"{statistics.median(r['solutions'] for r in runs):>5} {median('best_cost'):8.3f}")
    failed = [r["seed"] for r in runs if not r["ok"]]
    if failed:
        print(f"     no solution for seeds {failed}")


# ---------------------------------------------------------------------------------------------
# time split by stage kind (exclusive wall time inside the stages' compute methods)

# category -> (module under mtc.stages, class, methods)
STAGE_KINDS = {
    "IK (ComputeIK)": [("compute_ik", "ComputeIK", ("compute", "onNewSolution", "canCompute"))],
    "Connect (OMPL)": [("connect", "Connect", ("compute",))],
    "Cartesian moves (MoveRelative)": [("move_relative", "MoveRelative", ("compute",))],
    "MoveTo": [("move_to", "MoveTo", ("compute",))],
    "pose generators": [
        ("generate_pose", "GeneratePose", ("compute", "onNewSolution", "canCompute")),
        ("generate_grasp_pose", "GenerateGraspPose", ("compute", "onNewSolution")),
        ("generate_place_pose", "GeneratePlacePose", ("compute", "onNewSolution")),
    ],
    "scene changes (ModifyPlanningScene)": [
        ("modify_planning_scene", "ModifyPlanningScene", ("computeForward", "computeBackward")),
    ],
    "start state": [("current_state", "CurrentState", ("compute",)), ("fixed_state", "FixedState", ("compute",))],
    "filters (PredicateFilter)": [("predicate_filter", "PredicateFilter", ("onNewSolution",))],
}


class ExclusiveTimer:
    """Charges wall time to the innermost active category (a stack of wrapped calls)."""

    def __init__(self) -> None:
        self.totals: dict[str, float] = defaultdict(float)
        self.stack: list[str] = []
        self.last = 0.0

    def _charge(self) -> None:
        now = time.perf_counter()
        if self.stack:
            self.totals[self.stack[-1]] += now - self.last
        self.last = now

    def enter(self, category: str) -> None:
        self._charge()
        self.stack.append(category)

    def leave(self) -> None:
        self._charge()
        self.stack.pop()


def install_stage_timers(timer: ExclusiveTimer) -> list:
    """Wrap the stage classes' compute methods; returns what to restore."""
    import importlib

    restore = []
    for category, entries in STAGE_KINDS.items():
        for module_name, class_name, methods in entries:
            cls = getattr(importlib.import_module(f"mtc.stages.{module_name}"), class_name)
            for method in methods:
                if method not in cls.__dict__:
                    continue  # inherited: wrapped (or not) where it is defined
                original = cls.__dict__[method]

                def wrapper(self, *args, __original=original, __category=category, **kwargs):
                    timer.enter(__category)
                    try:
                        return __original(self, *args, **kwargs)
                    finally:
                        timer.leave()

                wrapper.__name__ = original.__name__
                setattr(cls, method, wrapper)
                restore.append((cls, method, original))
    return restore


def split_by_stage_kind(example: dict, seed: int, max_solutions: int) -> tuple[dict[str, float], float]:
    timer = ExclusiveTimer()
    restore = install_stage_timers(timer)
    try:
        task = make_seeded_task(example, seed)
        task.init()
        start = time.perf_counter()
        task.plan(max_solutions=max_solutions)
        total = time.perf_counter() - start
    finally:
        for cls, method, original in restore:
            setattr(cls, method, original)
    return dict(timer.totals), total


def print_split(totals: dict[str, float], total: float) -> None:
    print(f"  time split by stage kind (exclusive, plan() = {total:.3f} s):")
    rows = sorted(totals.items(), key=lambda kv: -kv[1])
    rows.append(("scheduling (engine, the rest)", total - sum(totals.values())))
    for category, seconds in rows:
        print(f"    {category:38s} {seconds:8.3f} s {100 * seconds / total:5.1f} %")


# ---------------------------------------------------------------------------------------------
# cProfile by module


def _module_of(filename: str) -> str:
    """A short module label for a profiled function's file ('' for compiled code)."""
    if filename in ("~", "") or filename.startswith("<"):
        return ""
    path = Path(filename)
    parts = path.with_suffix("").parts
    if "mtc" in parts:
        return ".".join(parts[len(parts) - 1 - parts[::-1].index("mtc"):])
    if "site-packages" in parts:
        return parts[parts.index("site-packages") + 1].split(".")[0]
    return path.stem


def profile_by_module(example: dict, seed: int, max_solutions: int) -> tuple[dict[str, float], float]:
    """Self time per module; compiled functions' time goes to their calling modules."""
    task = make_seeded_task(example, seed)
    task.init()
    profiler = cProfile.Profile()
    start = time.perf_counter()
    profiler.enable()
    task.plan(max_solutions=max_solutions)
    profiler.disable()
    total = time.perf_counter() - start
    stats = pstats.Stats(profiler).stats  # (file, line, name) -> (cc, nc, tt, ct, callers)
    by_module: dict[str, float] = defaultdict(float)
    for (filename, _line, _name), (_cc, _nc, tt, _ct, callers) in stats.items():
        module = _module_of(filename)
        if module:
            by_module[module] += tt
            continue
        # compiled code: split its self time over its callers by their share of the calls' time
        edge_times = {caller: edge[2] for caller, edge in callers.items()}
        weight = sum(edge_times.values())
        if weight <= 0:
            by_module["(compiled, no caller)"] += tt
            continue
        for caller, edge_tt in edge_times.items():
            by_module[_module_of(caller[0]) or "(compiled)"] += tt * edge_tt / weight
    return dict(by_module), total


def print_modules(by_module: dict[str, float], total: float, top: int = 14) -> None:
    profiled = sum(by_module.values())
    print(f"  cProfile self time by module (profiled {profiled:.3f} s; plan() {total:.3f} s under the profiler):")
    rows = sorted(by_module.items(), key=lambda kv: -kv[1])
    for module, seconds in rows[:top]:
        print(f"    {module:38s} {seconds:8.3f} s {100 * seconds / profiled:5.1f} %")
    rest = sum(seconds for _m, seconds in rows[top:])
    if rest:
        print(f"    {'(other modules)':38s} {rest:8.3f} s {100 * rest / profiled:5.1f} %")


# ---------------------------------------------------------------------------------------------


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=10, help="number of seeds (0, 1, ...)")
    parser.add_argument("--solutions", type=int, default=10, help="max_solutions of plan()")
    parser.add_argument("--example", choices=EXAMPLE_NAMES, action="append",
                        help="benchmark only this example (repeatable; default both)")
    parser.add_argument("--no-profile", action="store_true", help="skip the time split and cProfile")
    args = parser.parse_args(argv)

    mtc.robots.panda()  # load the robot once, outside every measurement
    results = {}
    for name in args.example or EXAMPLE_NAMES:
        example = load_example(name)
        runs = [run_once(example, seed, args.solutions) for seed in range(args.seeds)]
        print_runs(name, runs, args.solutions)
        results[name] = {"runs": runs}
        if not args.no_profile:
            totals, total = split_by_stage_kind(example, 0, args.solutions)
            print_split(totals, total)
            by_module, profiled_total = profile_by_module(example, 0, args.solutions)
            print_modules(by_module, profiled_total)
            results[name].update(split=totals, split_total=total, modules=by_module)
    mtc.reset_current_scene()
    return results


if __name__ == "__main__":
    main()
