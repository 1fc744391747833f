"""Scheduler overhead benchmark: serial [generator of N states, connector, generator of N states].

Enumerates all N x N solutions with MTC's mockups (no robot work: a generator spawns its
one scene again and again, the connector only creates an empty SubTrajectory) and prints
the total time, the time per connector call (wall clock and this process's CPU time, the
latter being less disturbed by other load) and the peak memory (tracemalloc; measured in a
separate run, as tracing slows Python down). Everything but the mockups' few lines is
engine overhead. Target (issue 3): under 50 us of engine overhead per connector call
and under 200 MB for N = 100.

The figures are medians over ``--repeat`` runs (default 3), as the machine may be shared.

Usage: python bench/engine_bench.py [--states N] [--repeat R] [--no-tracemalloc]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
import tracemalloc
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from mockups import ConnectMockup, GeneratorMockup, make_task  # noqa: E402


def run(states: int = 100, trace_memory: bool = True) -> dict:
    """Plan the benchmark task; return timing and memory figures."""
    task = make_task()
    # distinct costs so that ordering work is realistic (no ties between generator states)
    task.add(GeneratorMockup([float(i) for i in range(states)]))
    con = ConnectMockup()
    task.add(con)
    task.add(GeneratorMockup([float(100 * i) for i in range(states)]))
    task.init()  # loads nothing heavy: the toy robot is loaded by make_task already

    if trace_memory:
        tracemalloc.start()
    start = time.perf_counter()
    cpu_start = time.process_time()
    result = task.plan()
    total = time.perf_counter() - start
    cpu = time.process_time() - cpu_start
    peak = tracemalloc.get_traced_memory()[1] if trace_memory else 0
    if trace_memory:
        tracemalloc.stop()
    assert result, "benchmark task found no solution"
    n = task.numSolutions()
    assert n == states * states, f"expected {states * states} solutions, got {n}"
    return {
        "states": states,
        "solutions": n,
        "connector_calls": con.runs,
        "total_s": total,
        "per_call_us": 1e6 * total / con.runs,
        "cpu_s": cpu,
        "cpu_per_call_us": 1e6 * cpu / con.runs,
        "peak_mb": peak / 2**20,
    }


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=100, help="states per generator")
    parser.add_argument("--repeat", type=int, default=3, help="runs per figure (the median is shown)")
    parser.add_argument("--no-tracemalloc", action="store_true", help="time without memory tracing")
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error(f"--repeat must be at least 1, got {args.repeat}")
    runs = [run(args.states, False) for _ in range(args.repeat)]
    r = dict(runs[0])
    for key in ("total_s", "per_call_us", "cpu_s", "cpu_per_call_us"):
        r[key] = statistics.median(x[key] for x in runs)
    if not args.no_tracemalloc:
        r["peak_mb"] = statistics.median(run(args.states, True)["peak_mb"] for _ in range(args.repeat))
    print(f"{'runs (medians shown)':<28}{args.repeat:>12}")
    print(f"{'states per generator':<28}{r['states']:>12}")
    print(f"{'solutions':<28}{r['solutions']:>12}")
    print(f"{'connector calls':<28}{r['connector_calls']:>12}")
    print(f"{'total time [s]':<28}{r['total_s']:>12.3f}")
    print(f"{'time per connector call [us]':<28}{r['per_call_us']:>12.1f}")
    print(f"{'CPU time [s]':<28}{r['cpu_s']:>12.3f}")
    print(f"{'CPU per connector call [us]':<28}{r['cpu_per_call_us']:>12.1f}")
    if not args.no_tracemalloc:
        print(f"{'peak memory [MB]':<28}{r['peak_mb']:>12.1f}")


if __name__ == "__main__":
    main()
