"""Motion planning benchmark: mtc's OMPL pipeline (RRTConnect) against pyroboplan's RRT.

Both planners get the same problems in the same run:

* the MotionBenchMaker problems (``$MTC_MBM_DIR``, else ``shared/data/motion_bench_maker``
  beside the repository, else the repository's copy in ``bench/data``; every family folder
  there, e.g. ``table_pick``, ``box``, ``bookshelf_small``), built into an mtc
  ``PlanningScene`` from the problem's obstacles (one ``msgs.CollisionObject`` per primitive
  or mesh), its allowed collision matrix, and the fingers fixed at the start state's opening
  (clamped to the URDF's 0.04 m, as the baseline does);
* the table-and-shelf world of ``bench/problems.py`` with seeded start/goal pairs that mtc's
  collision checker accepts;
* with ``--generated N``: N problems each of MotionBenchMaker families the data subset does not
  ship (``cage``: reaching between two bars into a box; ``bookshelf_thin``, ``bookshelf_tall``:
  reaching into a shelf beside the cans on its boards; ``table_under_pick``: from under a table
  to the can on it), generated from MotionBenchMaker's scene configs with goals (and the
  under-the-table start) from mtc's IK.

Problems whose start or goal lies outside example-robot-data's joint limits or collides (with
its meshes, as the scene is built), or whose files hold what the loader cannot read (a plane, a
request without a joint goal), are reported (column "invalid", and listed with the reason
under the table), not planned by either planner.

Per family and planner: success rate, median and 90th-percentile planning time of the
solved problems (mtc: the whole request, i.e. start/goal checks, search, shortcutting, the
proof that every edge of the path is collision-free at every state on it (not only at
sampled states) and interpolation; pyroboplan: its ``plan()``, which does not shorten paths
and checks sampled states), median joint-space path length [rad] (Euclidean per segment), and
collision-checked states per second of planning time (mtc: the clearance tests of the proof
count as checked states). The speed-up is pyroboplan's median time over mtc's, on the
problems both solved.

Targets (issue 4): every valid problem solved within 1 s; median planning time under 20 ms
per family; at least 50x faster than pyroboplan. Under the table the run says, per target,
whether it was met and where not (:func:`verdicts`).

Run::

    python bench/motion_bench.py                      # full run (50 per family + 50 table-shelf)
    python bench/motion_bench.py --problems 5 --families box --no-baseline   # quick
    python bench/motion_bench.py --families --table-shelf 0 --generated 30   # the generated families
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import logging
import statistics
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

if __package__ in (None, ""):
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import mtc  # noqa: E402
from bench.problems import (  # noqa: E402
    ARM_JOINTS,
    FINGER_JOINTS,
    GENERATED_FAMILIES,
    READY_ARM,
    Obstacle,
    default_root,
    families as mbm_families,
    Problem,
    generated_problems,
    invalid_status,
    is_planned,
    limit_violations,
    load_family,
    panda_joint_limits,
    table_shelf_problems,
    table_shelf_world,
)
from mtc import msgs  # noqa: E402
from mtc.planners.ompl_pipeline import OMPLPipeline  # noqa: E402

log = logging.getLogger(__name__)

#: Issue 4's targets: every valid problem solved within this time [s], ...
TARGET_TIME_S = 1.0
#: ... a median planning time under this per family [ms], ...
TARGET_MEDIAN_MS = 20.0
#: ... and at least this many times faster than pyroboplan (median over median).
TARGET_SPEEDUP = 50.0

_KIND = {"box": msgs.SolidPrimitive.BOX, "sphere": msgs.SolidPrimitive.SPHERE,
         "cylinder": msgs.SolidPrimitive.CYLINDER, "cone": msgs.SolidPrimitive.CONE}


def collision_object(model: mtc.RobotModel, o: Obstacle) -> msgs.CollisionObject:
    """The ``msgs.CollisionObject`` of one obstacle (a primitive or an inline mesh)."""
    obj = msgs.CollisionObject(
        id=o.name.replace("/", "#"),  # "/" would read as an object's subframe
        header=msgs.Header(frame_id=model.model_frame),
        operation=msgs.CollisionObject.ADD,
    )
    pose = msgs.matrix_to_pose(o.pose)
    if o.kind == "mesh":
        obj.meshes = [msgs.Mesh(
            triangles=[msgs.MeshTriangle(vertex_indices=[int(i) for i in t]) for t in o.triangles],
            vertices=[msgs.Point(x=float(x), y=float(y), z=float(z)) for x, y, z in o.vertices],
        )]
        obj.mesh_poses = [pose]
    else:
        obj.primitives = [msgs.SolidPrimitive(type=_KIND[o.kind], dimensions=list(o.dims))]
        obj.primitive_poses = [pose]
    return obj


# ---------------------------------------------------------------------------------------------
# Scenes


def finger_opening(problem: Problem | None) -> float:
    """The problem's finger opening clamped to the URDF limits (MotionBenchMaker says 0.065 m,
    example-robot-data's Panda opens 0.04 m per finger)."""
    lo, hi = panda_joint_limits()[FINGER_JOINTS[0]]
    value = hi if problem is None else problem.start.get(FINGER_JOINTS[0], hi)
    return float(min(max(value, lo), hi))


def build_scene(model: mtc.RobotModel, obstacles: Sequence[Obstacle], allowed=(), finger: float = 0.04):
    """An mtc scene holding the obstacles, the allowed collision pairs (robot links only) and
    the fingers at ``finger``."""
    scene = mtc.PlanningScene(model)
    for o in obstacles:
        scene.apply_collision_object(collision_object(model, o))
    acm = scene.allowed_collision_matrix
    for a, b in allowed:
        if model.has_link_model(a) and model.has_link_model(b):
            acm.set_entry(a, b, True)
    scene.current_state.set_variable_positions({f: finger for f in FINGER_JOINTS})
    return scene


def problem_states(scene, problem: Problem):
    """(start, goal) robot states of a problem in its scene (fingers as the scene has them)."""
    start = scene.current_state.copy()
    start.set_variable_positions({j: problem.start[j] for j in ARM_JOINTS})
    goal = start.copy()
    goal.set_variable_positions({j: problem.goal[j] for j in ARM_JOINTS})
    return start, goal


def mtc_validity(model: mtc.RobotModel, obstacles: Sequence[Obstacle], finger: float = 0.04):
    """``is_valid(q7)`` through mtc's collision checker (for sampling benchmark problems)."""
    scene = build_scene(model, obstacles, (), finger)
    check = scene.state_validity_checker("panda_arm")
    q = scene.current_state.positions.copy()
    idx = [model.variable_index(j) for j in ARM_JOINTS]

    def is_valid(q7: np.ndarray) -> bool:
        q[idx] = q7
        return bool(check(q))

    # the checker does not keep its scene's collision set-up alive (see
    # /work/notes/requests_scene.md, item 2): hold the scene here
    is_valid.scene = scene
    return is_valid


#: IK attempts per hand pose of a generated problem's goal (a count, not a time: the problems
#: do not depend on the machine's speed).
GOAL_IK_ATTEMPTS = 20


def mtc_goal_tools(model: mtc.RobotModel, finger: float = 0.04):
    """``(is_valid(obstacles, q7), solve_ik(obstacles, hand_pose, rng))`` through mtc's collision
    checker (:func:`mtc_validity`, made once per world) and IK, for
    :func:`bench.problems.generated_problems`."""
    cache: dict = {}

    def check_of(obstacles):
        if cache.get("key") is not obstacles:
            cache.update(key=obstacles, check=mtc_validity(model, obstacles, finger))
        return cache["check"]

    def is_valid(obstacles, q7) -> bool:
        return check_of(obstacles)(q7)

    def solve_ik(obstacles, pose, rng):
        check = check_of(obstacles)
        state = check.scene.current_state.copy()
        state.set_joint_group_positions("panda_arm", READY_ARM)
        found = state.set_from_ik(
            "panda_arm", pose, tip="panda_hand", timeout=10.0, max_attempts=GOAL_IK_ATTEMPTS, rng=rng,
            is_valid=lambda s: check(s.get_joint_group_positions("panda_arm")),
        )
        return state.get_joint_group_positions("panda_arm") if found else None

    return is_valid, solve_ik


# ---------------------------------------------------------------------------------------------
# Runs


def run_mtc(model, problem: Problem, timeout: float, seed: int, pipeline: OMPLPipeline) -> dict:
    """Plan one problem with mtc's OMPL pipeline (RRTConnect)."""
    out = {"problem": problem.name, "success": False, "time_s": 0.0, "path_length": float("nan"),
           "checks": 0, "status": ""}
    violations = limit_violations(problem)
    if violations:
        out["status"] = invalid_status(violations)
        return out
    scene = build_scene(model, problem.obstacles, problem.allowed_collisions, finger_opening(problem))
    start, goal = problem_states(scene, problem)
    # a start or goal that collides (with this Panda's meshes) makes no valid problem either
    colliding = [f"{which} in collision: " + ", ".join(f"{a} - {b}" for a, b in sorted(pairs))
                 for which, state in (("start", start), ("goal", goal))
                 if (pairs := scene.get_collisions(state, problem.group))]
    if colliding:
        out["status"] = invalid_status(colliding)
        return out
    scene.is_state_colliding()  # build the collision set-up, as a scene in use has it
    t0 = time.perf_counter()
    result, traj = pipeline.plan_joint(
        scene, start, goal, problem.group, planner_id="RRTConnectkConfigDefault", timeout=timeout, seed=seed
    )
    out["time_s"] = time.perf_counter() - t0
    stats = pipeline.last_stats
    out["checks"] = stats.states_checked
    out["status"] = "solved" if result else result.message
    if result:
        positions = traj.positions
        if not (np.allclose(positions[0], problem.start_arm()) and np.allclose(positions[-1], problem.goal_arm())):
            raise RuntimeError(f"{problem.name}: mtc's path does not join start and goal")
        out.update(success=True, path_length=float(np.linalg.norm(np.diff(positions, axis=0), axis=1).sum()))
        out["dense_free"] = dense_free(scene, traj, problem.group, DENSE_STEP)
    return out


#: Joint step [rad] at which mtc's paths are re-checked after planning (not timed).
DENSE_STEP = 0.001


def dense_free(scene, traj, group: str, step: float) -> bool:
    """Whether the trajectory is collision-free at every state of its waypoints' straight
    interpolation at most ``step`` apart in every joint (mtc's checker, the group's pairs)."""
    idx = scene.robot_model.get_joint_model_group(group).variable_indices
    positions = traj.positions
    check = scene.state_validity_checker(group)
    q = traj[0].positions.copy()
    for a, b in zip(positions[:-1], positions[1:]):
        n = max(1, int(np.ceil(float(np.abs(b - a).max()) / step)))
        for k in range(n + 1):
            q[idx] = a + (b - a) * (k / n)
            if not check(q):
                return False
    return True


@contextlib.contextmanager
def _count_pinocchio_collision_calls(counter: list[int]):
    """Count ``pinocchio.computeCollisions`` calls (pyroboplan checks one state per call)."""
    import pinocchio

    original = pinocchio.computeCollisions

    def counting(*args, **kwargs):
        counter[0] += 1
        return original(*args, **kwargs)

    pinocchio.computeCollisions = counting
    try:
        yield
    finally:
        pinocchio.computeCollisions = original


def run_baseline(problem: Problem, timeout: float, seed: int) -> dict | None:
    """Plan one problem with pyroboplan's RRT (None when pyroboplan is not installed)."""
    try:
        from bench import baseline_pyroboplan
        baseline_pyroboplan._import_rrt()
    except ImportError:
        return None
    counter = [0]
    with _count_pinocchio_collision_calls(counter):
        r = baseline_pyroboplan.plan_pyroboplan(problem, timeout=timeout, seed=seed)
    r["checks"] = counter[0]
    return r


def summarize(results: Sequence[dict]) -> dict:
    """Success rate over the plannable problems, time percentiles and lengths of the solved."""
    planned = [r for r in results if is_planned(r)]
    solved = [r for r in planned if r["success"]]
    times = [r["time_s"] for r in solved]
    total_time = sum(r["time_s"] for r in planned)
    return {
        "n": len(results),
        "invalid": len(results) - len(planned),
        "planned": len(planned),
        "solved": len(solved),
        "rate": len(solved) / len(planned) if planned else float("nan"),
        "median_ms": 1e3 * statistics.median(times) if times else float("nan"),
        "p90_ms": 1e3 * float(np.percentile(times, 90)) if times else float("nan"),
        "max_ms": 1e3 * max(times) if times else float("nan"),
        "length": statistics.median(r["path_length"] for r in solved) if solved else float("nan"),
        "checks_per_s": sum(r["checks"] for r in planned) / total_time if total_time > 0 else float("nan"),
        "within_1s": sum(1 for t in times if t <= TARGET_TIME_S),
        # mtc only: solved paths found free when re-checked at DENSE_STEP
        "dense_free": sum(1 for r in solved if r.get("dense_free")) if any("dense_free" in r for r in solved) else None,
    }


def speedup(mtc_results: Sequence[dict], base_results: Sequence[dict]) -> float:
    """Median pyroboplan time over median mtc time, on the problems both solved."""
    both = [(m["time_s"], b["time_s"]) for m, b in zip(mtc_results, base_results) if m["success"] and b["success"]]
    if not both:
        return float("nan")
    return statistics.median(b for _, b in both) / statistics.median(m for m, _ in both)


def suites(families: Sequence[str] | None, problems: int | None, table_shelf: int, seed: int, model,
           generated: int = 0, generated_families: Sequence[str] = ()) -> list:
    out = []
    if families is None:
        families = mbm_families()
        if not families:
            log.warning("no MotionBenchMaker families under %s: none planned (set MTC_MBM_DIR to the folder "
                        "that holds the family folders)", default_root())
    for fam in families:
        ps = load_family(fam, keep_unreadable=True)  # an unreadable problem is reported, not planned
        out.append((ps[0].family if ps else fam, ps[:problems] if problems else ps))
    if table_shelf:
        is_valid = mtc_validity(model, table_shelf_world())
        out.append(("table_shelf", table_shelf_problems(table_shelf, seed, is_valid=is_valid)))
    if generated:
        is_valid, solve_ik = mtc_goal_tools(model)
        loaded = {name for name, _ in out}
        for fam in generated_families:
            ps = generated_problems(fam, generated, seed, is_valid=is_valid, solve_ik=solve_ik)
            if fam in loaded:  # a full MotionBenchMaker copy has this family: tell them apart
                ps = [dataclasses.replace(p, family=f"{fam}_generated") for p in ps]
            out.append((ps[0].family if ps else fam, ps))
    return out


def run(
    families: Sequence[str] | None = None,
    problems: int | None = None,
    table_shelf: int = 50,
    timeout: float = 5.0,
    baseline: bool = True,
    baseline_timeout: float = 10.0,
    seed: int = 0,
    verbose: bool = False,
    out=sys.stdout,
    generated: int = 0,
    generated_families: Sequence[str] = tuple(GENERATED_FAMILIES),
) -> list[dict]:
    """Run the benchmark and print a markdown table; returns one row dict per family.
    ``generated`` problems per family of ``generated_families`` are added (see
    :func:`bench.problems.generated_problems`)."""
    model = mtc.robots.panda()
    pipeline = OMPLPipeline()
    rows = []
    have_baseline = baseline and _baseline_available()
    for family, ps in suites(families, problems, table_shelf, seed, model, generated, generated_families):
        m_res, b_res = [], []
        for p in ps:
            r = run_mtc(model, p, timeout, seed, pipeline)
            m_res.append(r)
            if not have_baseline:
                b = None
            elif not is_planned(r):  # not planned by either planner
                b = dict(r)
            else:
                b = run_baseline(p, baseline_timeout, seed)
            if b is not None:
                b_res.append(b)
            if verbose:
                line = f"  {p.name:<22} mtc {r['status'][:40]:<40} {1e3 * r['time_s']:8.1f} ms {r['path_length']:6.2f} rad"
                if b is not None:
                    line += f" | pyroboplan {b['status'][:20]:<20} {1e3 * b['time_s']:9.1f} ms"
                print(line, file=out, flush=True)
        row = {"family": family, "mtc": summarize(m_res), "mtc_results": m_res}
        if b_res:
            row["pyroboplan"] = summarize(b_res)
            row["pyroboplan_results"] = b_res
            row["speedup"] = speedup(m_res, b_res)
        rows.append(row)
    print_table(rows, timeout, baseline_timeout, seed, out)
    return rows


def verdicts(rows: Sequence[dict]) -> list[str]:
    """One line per target of issue 4: met, or missed and where (families and problems), for
    the rows of :func:`run`. A problem not solved counts as not solved within the time."""
    slow = [f"{r['problem']} ({'%.0f ms' % (1e3 * r['time_s']) if r['success'] else 'not solved'})"
            for row in rows for r in row["mtc_results"]
            if is_planned(r) and not (r["success"] and r["time_s"] <= TARGET_TIME_S)]
    planned = sum(row["mtc"]["planned"] for row in rows)
    lines = [f"every valid problem solved within {TARGET_TIME_S:g} s: "
             + (f"met ({planned} of {planned})" if not slow
                else f"missed by {len(slow)} of {planned}: {', '.join(slow)}")]
    medians = [(row["family"], row["mtc"]["median_ms"]) for row in rows if row["mtc"]["solved"]]
    over = [f"{fam} ({ms:.1f} ms)" for fam, ms in medians if not ms < TARGET_MEDIAN_MS]
    lines.append(f"median under {TARGET_MEDIAN_MS:g} ms per family: "
                 + ("no family solved anything" if not medians else
                    f"met ({len(medians)} families)" if not over else f"missed on {', '.join(over)}"))
    ratios = [(row["family"], row["speedup"]) for row in rows if np.isfinite(row.get("speedup", np.nan))]
    shown = {fam: f"{np.floor(10 * x) / 10:.1f}x" for fam, x in ratios}  # (49.97 is not shown as 50.0)
    short = [f"{fam} ({shown[fam]})" for fam, x in ratios if not x >= TARGET_SPEEDUP]
    fast = [f"{fam} ({shown[fam]})" for fam, x in ratios if x >= TARGET_SPEEDUP]
    lines.append(f"at least {TARGET_SPEEDUP:g}x faster than pyroboplan: "
                 + ("not measured (no baseline results)" if not ratios else
                    "met on every family" if not short else
                    f"missed on {', '.join(short)}" + (f"; met on {', '.join(fast)}" if fast else "")))
    return lines


def _baseline_available() -> bool:
    try:
        from bench import baseline_pyroboplan

        baseline_pyroboplan._import_rrt()
        return True
    except ImportError:
        return False


def print_table(rows: Sequence[dict], timeout: float, baseline_timeout: float, seed: int, out=sys.stdout) -> None:
    print(
        f"\nmtc OMPL pipeline (RRTConnectkConfigDefault, timeout {timeout:g} s) vs pyroboplan RRT-Connect "
        f"(timeout {baseline_timeout:g} s), seed {seed}\n",
        file=out,
    )
    print(
        "| family | planner | problems | invalid | solved | success | <= 1 s | median [ms] | p90 [ms] | max [ms] "
        f"| path length [rad] | checked states/s | speed-up | free at {1e3 * DENSE_STEP:g} mrad |",
        file=out,
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|", file=out)
    for row in rows:
        for name in ("mtc", "pyroboplan"):
            s = row.get(name)
            if s is None:
                continue
            sp = f"{row['speedup']:.0f}x" if name == "mtc" and "speedup" in row else ""
            dense = "" if s.get("dense_free") is None else f"{s['dense_free']}/{s['solved']}"
            print(
                f"| {row['family']} | {name} | {s['n']} | {s['invalid']} | {s['solved']} | {s['rate']:.0%} "
                f"| {s['within_1s']} | {s['median_ms']:.1f} | {s['p90_ms']:.1f} | {s['max_ms']:.1f} "
                f"| {s['length']:.2f} | {s['checks_per_s']:,.0f} | {sp} | {dense} |",
                file=out,
            )
    # what the counts hide: each problem mtc did not plan (invalid) or did not solve, and why
    notes = [f"- {r['problem']}: {r['status']}" for row in rows for r in row.get("mtc_results", ())
             if not r["success"]]
    if notes:
        print("\nmtc did not plan or did not solve:", *notes, sep="\n", file=out)
    print("\ntargets (issue 4):", *(f"- {line}" for line in verdicts(rows)), sep="\n", file=out)
    out.flush()


def print_kinematics(out=sys.stdout) -> None:
    """owner A's IK and time parameterization numbers, when bench/kinematics_bench.py exists."""
    try:
        from bench import kinematics_bench
    except ImportError:
        return
    for name in ("bench_ik", "bench_time_parameterization"):
        fn = getattr(kinematics_bench, name, None)
        if fn is None:
            continue
        try:
            result = fn()
        except TypeError:
            continue  # needs arguments this script does not know
        if isinstance(result, dict):
            print(f"\n{name} (bench/kinematics_bench.py)\n\n| quantity | value |\n|---|---|", file=out)
            for key, value in _flatten(result):
                shown = f"{value:.4g}" if isinstance(value, float) else str(value)
                print(f"| {key} | {shown} |", file=out)
        elif result is not None:
            print(f"\n{name}: {result}", file=out)


def _flatten(d: dict, prefix: str = ""):
    for key, value in d.items():
        if isinstance(value, dict):
            yield from _flatten(value, f"{prefix}{key}.")
        else:
            yield f"{prefix}{key}", value


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--families", nargs="*", default=None,
                        help="MotionBenchMaker families (default: every family folder under the problem root)")
    parser.add_argument("--problems", type=int, default=None, help="first N problems per family (default: all)")
    parser.add_argument("--table-shelf", type=int, default=50, help="table-shelf start/goal pairs (0: none)")
    parser.add_argument("--timeout", type=float, default=5.0, help="mtc's planning time per problem [s]")
    parser.add_argument("--baseline-timeout", type=float, default=10.0, help="pyroboplan's time per problem [s]")
    parser.add_argument("--no-baseline", action="store_true", help="skip pyroboplan")
    parser.add_argument("--no-kinematics", action="store_true", help="skip the IK / time-parameterization numbers")
    parser.add_argument("--generated", type=int, default=0,
                        help="problems per generated MotionBenchMaker family (see --generated-families; 0: none)")
    parser.add_argument("--generated-families", nargs="*", default=list(GENERATED_FAMILIES), choices=list(GENERATED_FAMILIES))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("-v", "--verbose", action="store_true", help="one line per problem")
    args = parser.parse_args(argv)
    run(
        families=args.families,
        problems=args.problems,
        table_shelf=args.table_shelf,
        timeout=args.timeout,
        baseline=not args.no_baseline,
        baseline_timeout=args.baseline_timeout,
        seed=args.seed,
        verbose=args.verbose,
        generated=args.generated,
        generated_families=args.generated_families,
    )
    if not args.no_kinematics:
        print_kinematics()


if __name__ == "__main__":
    main()
