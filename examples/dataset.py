"""Make a dataset of pick-and-place plans, in parallel processes.

Each sample is the task of ``examples/pickplace.py`` with the box at a random place in front
of the robot, turned about the vertical, to be placed at a random spot on the robot's right,
and planned with its own planner seed. The samples are spread over ``--workers`` processes;
the dataset depends on ``--seed`` only, not on the number of workers or their speed (each
sample draws from its own random stream, and no plan is cut short by a clock unless it runs
into ``--timeout``); only the recorded planning times vary.

In ``--out`` it writes, per sample ``NNNNN``:

* ``sample_NNNNN.json``: the best solution's message (``solution.toJSON``; read it back with
  ``mtc.core.export.solution_from_json``);
* ``sample_NNNNN.npz``: that solution as arrays (``solution.toArrays()``: ``times``,
  ``positions``, ``velocities``, and ``joint_names`` naming their columns: the arm's seven
  joints and the gripper's ``panda_finger_joint1``);

and ``index.jsonl``: one line per sample, in sample order, with the box's pose, the place
position, the seed, whether it was solved, the cost, the planning time, and for a failed
sample why (``task.explainFailure()``). A failed sample is data too: it has no files but its
line says what failed. Each line is written as soon as its sample and all before it are
planned, right after the sample's files (by the main process, each under a temporary name
first), so a run that is stopped keeps the index of what it finished, with whole files. A stop
(Ctrl-C or SIGTERM) lets the samples begun end; workers whose main process is killed end too.

Run: ``python examples/dataset.py --samples 100 --workers 2 --out pick_place_dataset`` (a
folder that holds no dataset yet: no index and no sample files, not even a stopped run's).
``--view N`` plans sample ``N`` again and shows it in the browser, writing nothing; given the
dataset's ``--seed`` and ``--solutions`` it is the same plan (the sample is drawn from its own
stream; more solutions can find a cheaper best one).
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import multiprocessing
import os
import signal
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))  # examples/ (for the pickplace task)

import pickplace  # noqa: E402
from _demo import run_example  # noqa: E402  (examples/_demo.py: plan, report, --view)

#: Where the box is drawn from: x and y [m] in front of the robot, at pickplace's height.
OBJECT_X, OBJECT_Y, OBJECT_Z = (0.30, 0.55), (-0.30, 0.30), 0.285
#: Where it is placed: at a distance [m] from the base, at an angle [rad] on the robot's right.
PLACE_RADIUS, PLACE_ANGLE, PLACE_Z = (0.45, 0.65), (-2.0, -1.1), (0.0, 0.2)


def draw_sample(seed: int, index: int) -> dict:
    """The box pose, place position and planner seed of sample ``index`` (its own stream)."""
    rng = np.random.default_rng([seed, index])
    radius, angle = rng.uniform(*PLACE_RADIUS), rng.uniform(*PLACE_ANGLE)
    return {
        "index": index,
        "object_position": [float(rng.uniform(*OBJECT_X)), float(rng.uniform(*OBJECT_Y)), OBJECT_Z],
        "object_yaw": float(rng.uniform(-math.pi / 2, math.pi / 2)),
        "place_position": [float(radius * math.cos(angle)), float(radius * math.sin(angle)),
                           float(rng.uniform(*PLACE_Z))],
        "seed": int(rng.integers(2**31)),
    }


def sample_task(sample: dict, timeout: float = 60.0):
    """The pick-and-place task of a sample (it sets up the current scene with the box)."""
    task = pickplace.make_task(sample["object_position"], sample["object_yaw"], sample["place_position"],
                               sample["seed"])
    task.timeout = timeout
    return task


def plan_sample(job: tuple[dict, int, float]) -> tuple[dict, tuple | None]:
    """Plan one sample: its ``index.jsonl`` record, and the contents of its files (the best
    solution's JSON text and arrays; None if not solved), which the main process writes."""
    sample, max_solutions, timeout = job
    task = sample_task(sample, timeout)
    start = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()):  # (a failed plan prints its tree, as MTC's)
        result = task.plan(max_solutions)
    record = dict(sample, solved=bool(result), plan_s=round(time.perf_counter() - start, 4))
    if not result:
        why = io.StringIO()
        task.explainFailure(why)
        record.update(cost=None, solutions=0, failure=why.getvalue().strip() or str(result))
        return record, None
    best = task.solutions[0]
    arrays = best.toArrays()
    record.update(cost=best.cost, solutions=len(task.solutions))
    return record, (best.toJSON(), {"times": arrays.times, "positions": arrays.positions,
                                    "velocities": arrays.velocities, "joint_names": np.array(arrays.joint_names)})


def write_sample(folder: Path, index: int, files: tuple) -> None:
    """Write a sample's files, each under a temporary name first: a stopped run leaves no
    half-written file under a sample's name."""
    text, arrays = files
    stem = folder / f"sample_{index:05d}"
    part = folder / f".sample_{index:05d}.part"
    part.write_text(text)
    os.replace(part, f"{stem}.json")
    with open(part, "wb") as f:
        np.savez_compressed(f, **arrays)
    os.replace(part, f"{stem}.npz")


def _worker_init() -> None:
    """A pool worker: Ctrl-C stops the main process only (which then ends the samples begun),
    no second search of its own (the pool keeps every core busy, see mtc.planners._race), and
    it ends when the process that started it is gone (killed: nothing would read its work)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    os.environ["MTC_PARALLEL_SEARCH"] = "0"
    parent = os.getppid()

    def watch():
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


def bad_arguments(samples: int, workers: int, seed: int, max_solutions: int, timeout: float) -> str | None:
    """What is wrong with ``make_dataset``'s numbers, or None."""
    if samples < 0 or workers < 1 or seed < 0 or max_solutions < 1 or not timeout > 0:
        return ("need samples >= 0, workers >= 1, seed >= 0, max_solutions >= 1 and a positive timeout, got "
                f"samples={samples}, workers={workers}, seed={seed}, max_solutions={max_solutions}, timeout={timeout}")
    return None


def make_dataset(out: str | os.PathLike, samples: int, workers: int = 1, seed: int = 0,
                 max_solutions: int = 1, timeout: float = 60.0) -> list[dict]:
    """Plan ``samples`` samples over ``workers`` processes into ``out``; returns the records
    (also written to ``out/index.jsonl``, in sample order, each as soon as it and all before it
    are planned)."""
    error = bad_arguments(samples, workers, seed, max_solutions, timeout)
    if error:
        raise ValueError(error)
    folder = Path(out)
    if folder.is_dir() and any(p.name == "index.jsonl" or p.name.lstrip(".").startswith("sample_")
                               for p in folder.iterdir()):
        raise FileExistsError(f"{out} holds a dataset already (index.jsonl or sample files, maybe of a stopped run): "
                              "choose another folder or remove it")
    folder.mkdir(parents=True, exist_ok=True)
    jobs = [(draw_sample(seed, i), max_solutions, timeout) for i in range(samples)]
    records = []
    workers = min(workers, max(1, samples))
    with open(folder / "index.jsonl", "w") as index, contextlib.ExitStack() as stack:
        if workers == 1:
            planned = map(plan_sample, jobs)
        else:
            # (spawned, on every platform: a worker's parent is then this process, which it
            # watches; with the forkserver, Python 3.14's default on Linux, it would be the server)
            pool = stack.enter_context(ProcessPoolExecutor(max_workers=workers, initializer=_worker_init,
                                                           mp_context=multiprocessing.get_context("spawn")))
            # (map yields in the sample order; closed first on a stop, it cancels the samples not begun)
            planned = stack.enter_context(contextlib.closing(pool.map(plan_sample, jobs)))
        # a sample's files, then its index line, a stop waiting for both (_Stop): the files of
        # every listed sample are whole (only a SIGKILL between the two leaves files unlisted)
        for record, files in planned:
            with _STOP.held():
                if files is not None:
                    write_sample(folder, record["index"], files)
                index.write(json.dumps(record) + "\n")
                index.flush()
            records.append(record)
    return records


def main(argv: list[str] | None = None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, default=20, help="number of samples (default 20)")
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 1, help="processes (default: one per core)")
    parser.add_argument("--out", default="pick_place_dataset", help="output folder")
    parser.add_argument("--seed", type=int, default=0, help="the dataset's seed")
    parser.add_argument("--solutions", type=int, default=1,
                        help="solutions to plan per sample; the best is saved (default 1)")
    parser.add_argument("--timeout", type=float, default=60.0, help="planning time limit per sample [s]")
    parser.add_argument("--view", type=int, metavar="N",
                        help="plan sample N again and show it in the browser (writes nothing)")
    args = parser.parse_args(argv)
    if args.view is not None:
        if args.view < 0 or args.seed < 0 or args.solutions < 1 or not args.timeout > 0:
            parser.error("--view and --seed take numbers >= 0, --solutions one >= 1, --timeout one > 0")
        sample = draw_sample(args.seed, args.view)
        return run_example(lambda: sample_task(sample, args.timeout), __doc__, ["--view"], args.solutions)
    error = bad_arguments(args.samples, args.workers, args.seed, args.solutions, args.timeout)
    if error:
        parser.error(error)
    start = time.perf_counter()
    # a stop (Ctrl-C, or `kill`'s SIGTERM) ends the samples begun and keeps the index of those
    # listed, without a traceback
    handlers = {sig: signal.signal(sig, _STOP.handle) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        records = make_dataset(args.out, args.samples, args.workers, args.seed, args.solutions, args.timeout)
    except FileExistsError as e:
        parser.error(str(e))
    except KeyboardInterrupt:
        print(f"stopped: {Path(args.out) / 'index.jsonl'} lists the samples planned so far", file=sys.stderr)
        raise SystemExit(130) from None
    except OSError as e:  # (--out under a file, or where there is no write access)
        parser.error(f"cannot write the dataset in {args.out}: {e.strerror or e}")
    finally:
        for sig, handler in handlers.items():
            signal.signal(sig, handler)
    solved = sum(r["solved"] for r in records)
    print(f"{solved} of {len(records)} samples solved in {time.perf_counter() - start:.1f} s "
          f"with {args.workers} worker(s); files and index.jsonl in {args.out}")
    return records


class _Stop:
    """main()'s handler of Ctrl-C and SIGTERM: a KeyboardInterrupt, but not while a sample's
    files and index line are being written (:meth:`held`): then right after."""

    def __init__(self):
        self.holding = self.pending = False

    def handle(self, _signum, _frame):
        if not self.holding:
            raise KeyboardInterrupt
        self.pending = True

    @contextlib.contextmanager
    def held(self):
        self.holding = True
        try:
            yield
        finally:
            self.holding = False
        if self.pending:
            self.pending = False
            raise KeyboardInterrupt


_STOP = _Stop()


if __name__ == "__main__":
    main()
