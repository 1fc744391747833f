"""Scheduler overhead benchmark: serial [generator of N states, connector, generator of N states].

Enumerates all N x N solutions with MTC's mockups (no robot work: scenes are created once
per state and never changed) and prints total time, time per connector call and peak
memory (tracemalloc). Target (issue 3): under 50 us of engine overhead per connector call
and under 200 MB for N = 100.

Usage: python bench/engine_bench.py [--states N] [--no-tracemalloc]
"""

from __future__ import annotations

import argparse
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

    mockup_time = [0.0]
    original = con.compute

    def timed_compute(from_state, to_state):
        # the connector's own work (creating the solution) is not engine overhead... but
        # connect() inside it is: measure only the mockup's part before connect()
        start = time.perf_counter()
        original(from_state, to_state)
        mockup_time[0] += time.perf_counter() - start

    if trace_memory:
        tracemalloc.start()
    start = time.perf_counter()
    result = task.plan()
    total = time.perf_counter() - start
    peak = tracemalloc.get_traced_memory()[1] if trace_memory else 0
    if trace_memory:
        tracemalloc.stop()
    assert result, "benchmark task found no solution"
    n = task.numSolutions()
    assert n == states * states, f"expected {states * states} solutions, got {n}"
    del timed_compute
    return {
        "states": states,
        "solutions": n,
        "connector_calls": con.runs,
        "total_s": total,
        "per_call_us": 1e6 * total / con.runs,
        "peak_mb": peak / 2**20,
    }


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--states", type=int, default=100, help="states per generator")
    parser.add_argument("--no-tracemalloc", action="store_true", help="time without memory tracing")
    args = parser.parse_args(argv)
    r = run(args.states, not args.no_tracemalloc)
    print(f"{'states per generator':<28}{r['states']:>12}")
    print(f"{'solutions':<28}{r['solutions']:>12}")
    print(f"{'connector calls':<28}{r['connector_calls']:>12}")
    print(f"{'total time [s]':<28}{r['total_s']:>12.3f}")
    print(f"{'time per connector call [us]':<28}{r['per_call_us']:>12.1f}")
    if not args.no_tracemalloc:
        print(f"{'peak memory [MB]':<28}{r['peak_mb']:>12.1f}")


if __name__ == "__main__":
    main()
