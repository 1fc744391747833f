"""Planning-scene benchmark: ``diff()`` cost and full collision checks of the Panda.

Measures, in one run:
* ``diff()`` of a scene holding 20 objects (median over repeats) [us];
* full collision checks (self + world) of the Panda against 10 primitives at random states,
  through ``PlanningScene.state_validity_checker`` and, side by side on the same geometry
  and collision pairs, a plain loop over ``pinocchio.computeCollisions``.

Run: ``python bench/scene_bench.py [--states N] [--repeats R]``
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
import pinocchio as pin

import mtc
from mtc import msgs


def random_primitives(n: int, seed: int) -> list[msgs.CollisionObject]:
    """``n`` boxes, spheres and cylinders scattered around the Panda's workspace."""
    rng = np.random.default_rng(seed)
    objects = []
    for i in range(n):
        kind = [msgs.SolidPrimitive.BOX, msgs.SolidPrimitive.SPHERE, msgs.SolidPrimitive.CYLINDER][i % 3]
        dims = {1: [0.15, 0.15, 0.15], 2: [0.08], 3: [0.3, 0.05]}[kind]
        # keep obstacles away from the base so that most random states are collision-free
        r, phi = rng.uniform(0.35, 0.8), rng.uniform(-np.pi, np.pi)
        pos = msgs.Point(x=r * np.cos(phi), y=r * np.sin(phi), z=rng.uniform(0.05, 0.9))
        objects.append(
            msgs.CollisionObject(
                id=f"obstacle{i}",
                header=msgs.Header(frame_id="world"),
                primitives=[msgs.SolidPrimitive(type=kind, dimensions=dims)],
                primitive_poses=[msgs.Pose(position=pos)],
            )
        )
    return objects


def bench_diff(repeats: int) -> float:
    scene = mtc.PlanningScene(mtc.robots.panda())
    for obj in random_primitives(20, seed=1):
        scene.apply_collision_object(obj)
    scene.is_state_colliding()  # build the collision set-up, as a planning scene in use has
    samples = []
    for _ in range(repeats):
        n = 2000
        t = time.perf_counter()
        for _ in range(n):
            scene.diff()
        samples.append((time.perf_counter() - t) / n * 1e6)
    return statistics.median(samples)


def bench_collisions(n_states: int, repeats: int, seed: int = 0) -> dict:
    model = mtc.robots.panda()
    scene = mtc.PlanningScene(model)
    for obj in random_primitives(10, seed=2):
        scene.apply_collision_object(obj)
    state = scene.current_state
    rng = np.random.default_rng(seed)
    Q = []
    for _ in range(n_states):
        state.set_to_random_positions(rng=rng)
        Q.append(state.positions.copy())
    Q = np.array(Q)

    is_valid = scene.state_validity_checker()
    env = scene._collision_env()  # the same geometry, frame and collision pairs for the baseline
    pm = env.pm
    data = pm.createData()
    gm = env.geom_model
    gd = gm.createData()

    def run_mtc():
        return sum(not is_valid(q) for q in Q)

    def run_plain():
        return sum(bool(pin.computeCollisions(pm, data, gm, gd, q, True)) for q in Q)

    results = {"mtc": [], "plain": []}
    colliding = {}
    for _ in range(repeats):
        for name, fn in (("mtc", run_mtc), ("plain", run_plain)):
            t = time.perf_counter()
            colliding[name] = fn()
            results[name].append(n_states / (time.perf_counter() - t))
    if colliding["mtc"] != colliding["plain"]:
        raise AssertionError(f"checkers disagree: {colliding}")
    return {
        "mtc_states_per_s": statistics.median(results["mtc"]),
        "plain_states_per_s": statistics.median(results["plain"]),
        "colliding_fraction": colliding["mtc"] / n_states,
        "pairs": len(env.pairs),
    }


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=5000)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    diff_us = bench_diff(args.repeats)
    coll = bench_collisions(args.states, args.repeats)
    ratio = coll["mtc_states_per_s"] / coll["plain_states_per_s"]
    print("| measure | value |")
    print("|---|---|")
    print(f"| diff() of a 20-object scene, median | {diff_us:.2f} us |")
    print(f"| collision checks, mtc (broad phase) | {coll['mtc_states_per_s']:,.0f} states/s |")
    print(f"| collision checks, plain pinocchio.computeCollisions loop | {coll['plain_states_per_s']:,.0f} states/s |")
    print(f"| ratio mtc / plain | {ratio:.2f} |")
    print(f"| colliding states | {coll['colliding_fraction']:.1%} of {args.states}, {coll['pairs']} pairs |")
    return {"diff_us": diff_us, "ratio": ratio, **coll}


if __name__ == "__main__":
    main()
