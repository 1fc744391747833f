"""Two searches raced by their state checks.

A sampling planner's run time on a hard problem depends mostly on its random draws: a search
that is stuck after some thousand checks is often solved quickly by a second search with
other draws. :func:`race` runs such a second search beside the first and takes the path of
the one that finds it with fewer checks. Checks, not seconds, are the clock, so the winner
does not depend on the machine's speed or load: the same seeds give the same path.

Where the process can fork (Linux, two or more cores, no other threads), the second search
runs in a child process on another core and the race costs the wall time of the faster
search. Elsewhere, or with :data:`PARALLEL` off, the two take turns in this process and give
the same answer, at the cost of both searches' checks.

A search is an object with

* ``checks``: the state checks it has made so far (an int that only grows), and
* ``step(halt)``: run its next stretch (a turn of its planners) and return None when the
  stretch ran out of its own budget (the search goes on), else the end of the search: a tuple
  whose first item is the path (None for a failure). ``halt`` is None or a callable that the
  search calls between its checks; once it returns True the stretch stops (and returns None).
  Stopping a stretch must not change what it does before it stops.

The second search starts at ``offset`` checks of the first one's clock (the checks the first
made before the race): it wins if ``offset + b.checks`` at its end is less than ``a.checks`` at
the first one's end (a tie goes to the first).
"""

from __future__ import annotations

import logging
import mmap
import os
import pickle
import signal
import struct
import sys
import threading

log = logging.getLogger(__name__)

#: Run the second search in a child process where the platform allows it (the answer is the
#: same either way). The environment variable ``MTC_PARALLEL_SEARCH=0`` turns it off, e.g. for
#: a pool of workers that already keeps every core busy.
PARALLEL = os.environ.get("MTC_PARALLEL_SEARCH", "1") != "0"

_NOT_DONE = -1
_NO_PATH = 1 << 62  # a search that ended without a path (it wins only over another such)
_SLOT = struct.Struct("q")


def can_fork() -> bool:
    """Whether the second search may run in a child process here."""
    if not PARALLEL or not sys.platform.startswith("linux") or not hasattr(os, "fork"):
        return False
    # forking a process with other threads may leave the child with their locks held
    if threading.active_count() != 1:
        return False
    return len(os.sched_getaffinity(0)) >= 2


def race(a, b, offset: int, parallel: bool | None = None):
    """Race search ``b`` (starting at ``offset`` on ``a``'s clock) against ``a``: (winner, end,
    b_checks), with winner 0 (``a``) or 1 (``b``), the winner's end tuple, and the checks ``b``
    made (in the child process, where it ran there). ``parallel``: None decides by
    :func:`can_fork`."""
    if parallel is None:
        parallel = can_fork()
    if parallel:
        return _forked(a, b, offset)
    return _in_turns(a, b, offset)


def _end_value(search, offset: int, end) -> int:
    return offset + search.checks if end[0] is not None else _NO_PATH


def _in_turns(a, b, offset: int):
    searches, offsets = (a, b), (0, offset)
    ends: list = [None, None]  # end tuples
    at: list = [None, None]  # the clock at each search's end

    def clock(i: int) -> int:
        return offsets[i] + searches[i].checks

    while at[0] is None or at[1] is None:
        if at[0] is None and at[1] is None:
            i, halt = (0 if clock(0) <= clock(1) else 1), None
        elif at[0] is not None:
            if at[0] <= clock(1):
                break  # b can no longer end first
            i, cap = 1, at[0]
            halt = lambda: clock(1) >= cap  # noqa: E731
        else:
            if clock(0) > at[1]:
                break  # a can no longer end first
            i, cap = 0, at[1]
            halt = lambda: clock(0) > cap  # noqa: E731
        end = searches[i].step(halt)
        if end is not None:
            ends[i] = end
            at[i] = _end_value(searches[i], offsets[i], end)
    winner = 0 if at[0] is not None and (at[1] is None or at[0] <= at[1]) else 1
    return winner, ends[winner], b.checks


def _forked(a, b, offset: int):
    shared = mmap.mmap(-1, 2 * _SLOT.size)  # the clock at each search's end (shared with the child)
    _SLOT.pack_into(shared, 0, _NOT_DONE)
    _SLOT.pack_into(shared, _SLOT.size, _NOT_DONE)
    read_fd, write_fd = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: search b, report, exit without running the parent's clean-up
        status = 1
        try:
            os.close(read_fd)
            report = _child(b, offset, shared)
            with os.fdopen(write_fd, "wb") as out:
                out.write(report)
            status = 0
        finally:
            os._exit(status)
    os.close(write_fd)
    try:
        end_a, at_a = _parent(a, shared)
        _SLOT.pack_into(shared, 0, at_a)  # (b stops once it cannot end first)
        with os.fdopen(read_fd, "rb") as inp:
            data = inp.read()
        os.waitpid(pid, 0)
        pid = 0
    finally:
        if pid:  # interrupted: the child is not needed any more
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
    if not data:  # the child died: a's result alone (finished if it stopped for b)
        log.warning("the second search's process ended without a result; going on with the first")
        while end_a is None:
            end_a = a.step(None)
        return 0, end_a, 0
    at_b, end_b, b_checks = pickle.loads(data)
    if end_a is not None and (at_b is None or at_a <= at_b):
        return 0, end_a, b_checks
    return 1, end_b, b_checks


def _parent(a, shared):
    """Search ``a`` until it ends or can no longer end before ``b`` has: (end or None, the
    clock at its end or :data:`_NO_PATH`)."""

    def b_ended_before() -> bool:
        at_b = _SLOT.unpack_from(shared, _SLOT.size)[0]
        return at_b != _NOT_DONE and a.checks > at_b

    while not b_ended_before():
        end = a.step(b_ended_before)
        if end is not None:
            return end, _end_value(a, 0, end)
    return None, _NO_PATH


def _child(b, offset: int, shared) -> bytes:
    """Search ``b`` in the child process: the pickled (clock at its end or None where it
    stopped because ``a`` ended first, end, checks); its clock is also put in ``shared``."""

    def a_ended_before() -> bool:
        at_a = _SLOT.unpack_from(shared, 0)[0]
        return at_a != _NOT_DONE and offset + b.checks >= at_a

    at_b, end = None, None
    while not a_ended_before():
        end = b.step(a_ended_before)
        if end is not None:
            at_b = _end_value(b, offset, end)
            break
    # (the clock first: a stops on it; the result may be larger than the pipe holds)
    _SLOT.pack_into(shared, _SLOT.size, _NO_PATH if at_b is None else at_b)
    return pickle.dumps((at_b, end if at_b is not None else None, b.checks))
