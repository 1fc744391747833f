"""Two searches raced by their state checks.

A sampling planner's run time on a hard problem depends mostly on its random draws: a search
that is stuck after some thousand checks is often solved quickly by a second search with
other draws. :func:`race` runs such a second search beside the first and takes the path of
the one that finds it with fewer checks. Checks, not seconds, are the clock, so the winner
does not depend on the machine's speed or load: the same seeds give the same path, unless a
search runs into the request's time limit first.

Where the process can fork (:func:`can_fork`: Linux, two or more cores, no other Python
threads), the second search runs in a child process on another core and the race costs the
wall time of the faster search. Elsewhere the two take turns in this process and give the same
answer, at the cost of both searches' time (more where one runs a whole turn past the other's
end), so a request close to its time limit can time out there where it succeeds forked.

A search is an object with

* ``checks``: the state checks it has made so far (an int that only grows), and
* ``step(halt)``: run its next stretch (a turn of its planners) and return None when the
  stretch ran out of its own budget (the search goes on), else the end of the search: a tuple
  whose first item is the path (None for a failure). ``halt`` is None or a callable that the
  search asks from time to time (OMPL: between its planner's iterations); once it returns True
  the stretch stops and returns None, and the race does not step that search again. Stopping
  a stretch must not change what it does before it stops.

The second search starts at ``offset`` checks of the first one's clock (the checks the first
made before the race): it wins if ``offset + b.checks`` at its end is less than ``a.checks`` at
the first one's end (a tie goes to the first).
"""

from __future__ import annotations

import ctypes
import logging
import mmap
import os
import pickle
import select
import signal
import sys
import threading
import time
import traceback
import warnings

log = logging.getLogger(__name__)

#: Run the second search in a child process where the platform allows it (the answer is the
#: same either way). The environment variable ``MTC_PARALLEL_SEARCH=0`` also turns it off (read
#: at each race), e.g. for a pool of workers that already keeps every core busy.
PARALLEL = True

_NOT_DONE = -1
_ERROR = -2  # the child's search raised
_NO_PATH = 1 << 62  # a search that ended without a path (it wins only over another such)
#: How long the parent waits for the child past the request's deadline before it kills it [s].
_GRACE = 1.0
_PR_SET_PDEATHSIG = 1


def can_fork() -> bool:
    """Whether the second search may run in a child process here."""
    if not PARALLEL or os.environ.get("MTC_PARALLEL_SEARCH", "1") == "0":
        return False
    if not sys.platform.startswith("linux") or not hasattr(os, "fork"):
        return False
    # forking a process with other Python threads may leave the child with their locks held;
    # with SIGCHLD ignored the child could not be waited for
    if threading.active_count() != 1 or signal.getsignal(signal.SIGCHLD) is signal.SIG_IGN:
        return False
    return len(os.sched_getaffinity(0)) >= 2


def race(a, b, offset: int, deadline: float, parallel: bool | None = None):
    """Race search ``b`` (starting at ``offset`` on ``a``'s clock) against ``a``: (winner, end,
    checks), with winner 0 (``a``) or 1 (``b``), the winner's end tuple, and the checks both
    searches made up to the winner's end on the common clock (the same number however the
    race ran). ``deadline`` (``time.perf_counter()``) is the searches' own time limit.
    ``parallel``: None decides by :func:`can_fork`.

    Should the child process die without a report, or still run a second past the deadline,
    it is killed and ``a`` wins alone (a warning is logged): where it had been halted, it is
    stepped on to its end, and the checks are its own."""
    if parallel is None:
        parallel = can_fork()
    (at_a, end_a), report = _forked(a, b, offset, deadline) if parallel else _in_turns(a, b, offset)
    if report is None:  # the child died without a report
        log.warning("the second search's process ended without a result; going on with the first")
        return 0, end_a if end_a is not None else _finish_alone(a), a.checks
    at_b, end_b, b_checks = report
    winner = 0 if at_a is not None and (at_b is None or at_a <= at_b) else 1
    end_clock = (at_a, at_b)[winner]
    # each search's checks up to the winner's end (the loser may have run past it)
    checks = min(a.checks, end_clock) + max(0, min(offset + b_checks, end_clock) - offset)
    return winner, (end_a, end_b)[winner], checks


def _a_lost(a_clock: int, at_b: int) -> bool:
    """Whether ``a`` can no longer end first, ``b`` having ended at ``at_b`` (a tie is a's)."""
    return a_clock > at_b


def _b_lost(b_clock: int, at_a: int) -> bool:
    """Whether ``b`` can no longer end first, ``a`` having ended at ``at_a``."""
    return b_clock >= at_a


def _end_value(clock: int, end) -> int:
    return clock if end[0] is not None else _NO_PATH


def _in_turns(a, b, offset: int):
    """((clock at a's end or None where it lost, end), (the same for b, b's checks)): the
    search whose clock is behind runs its next stretch, until one has ended and the other can
    no longer end first."""
    searches = (a, b)
    ends: list = [None, None]
    at: list = [None, None]

    def clock(i: int) -> int:
        return searches[i].checks + (offset if i else 0)

    while at[0] is None or at[1] is None:
        if at[0] is None and at[1] is None:
            i, halt = (0 if clock(0) <= clock(1) else 1), None
        elif at[0] is not None:
            if _b_lost(clock(1), at[0]):
                break
            i, halt = 1, lambda: _b_lost(clock(1), at[0])
        else:
            if _a_lost(clock(0), at[1]):
                break
            i, halt = 0, lambda: _a_lost(clock(0), at[1])
        end = searches[i].step(halt)
        if end is not None:
            ends[i], at[i] = end, _end_value(clock(i), end)
    return (at[0], ends[0]), (at[1], ends[1], b.checks)


def _forked(a, b, offset: int, deadline: float):
    """As :func:`_in_turns`, with ``b`` in a child process; b's part is None where the child
    died without a report (or was still running past the deadline)."""
    shared = _shared_clocks()  # the clock at each search's end
    read_fd, write_fd = os.pipe()
    parent = os.getpid()
    try:
        with warnings.catch_warnings():
            # Python 3.12+ warns of fork() in a process with native threads: numpy's OpenBLAS
            # pool, which registers its own fork handlers (can_fork rules out Python threads)
            warnings.filterwarnings("ignore", r"This process .* is multi-threaded", DeprecationWarning)
            pid = os.fork()
    except OSError as error:  # (out of processes or memory) the same race, in turns
        os.close(read_fd)
        os.close(write_fd)
        log.warning("could not fork the second search (%s); the two take turns", error)
        return _in_turns(a, b, offset)
    if pid == 0:  # the child: search b, report, exit without running the parent's clean-up
        try:
            os.close(read_fd)
            _child_setup(parent)
            report = _child(b, offset, shared)
        except BaseException:
            shared[1] = _ERROR
            report = pickle.dumps(("error", traceback.format_exc()))
        try:
            with os.fdopen(write_fd, "wb") as out:
                out.write(report)
        finally:
            os._exit(0)
    os.close(write_fd)
    inp = os.fdopen(read_fd, "rb")
    try:
        at_a, end_a = _parent(a, shared)
        shared[0] = _NO_PATH if at_a is None else at_a  # (b stops once it lost)
        data = _read_until(inp, deadline + _GRACE)
        if data is None:  # past the deadline (a stuck child)
            _kill(pid)
        _wait(pid)
        pid = 0
    finally:
        inp.close()
        if pid:  # interrupted: the child is not needed any more
            _kill(pid)
            _wait(pid)
    if not data:
        return (at_a, end_a), None
    report = pickle.loads(data)
    if report[0] == "error":
        raise RuntimeError(f"the second search failed in its process:\n{report[1]}")
    return (at_a, end_a), report


def _shared_clocks():
    """Two integers in memory that a forked child shares: machine words, each written and read
    whole (``struct.pack_into`` clears its bytes before it writes them, so the other process
    could read a torn 0)."""
    words = (ctypes.c_int64 * 2).from_buffer(mmap.mmap(-1, 2 * ctypes.sizeof(ctypes.c_int64)))
    words[0] = words[1] = _NOT_DONE
    return words


def _parent(a, shared):
    """Search ``a`` until it ends or can no longer end first: (clock at its end or None, end)."""

    def lost() -> bool:
        at_b = shared[1]
        return at_b == _ERROR or (at_b != _NOT_DONE and _a_lost(a.checks, at_b))

    while not lost():
        end = a.step(lost)
        if end is not None:
            return _end_value(a.checks, end), end
    return None, None


def _child(b, offset: int, shared) -> bytes:
    """Search ``b`` in the child process: the pickled (clock at its end or None where it
    stopped because ``a`` ended first, end, checks); the clock also goes into ``shared``."""

    def lost() -> bool:
        at_a = shared[0]
        return at_a != _NOT_DONE and _b_lost(offset + b.checks, at_a)

    at_b, end = None, None
    while not lost():
        end = b.step(lost)
        if end is not None:
            at_b = _end_value(offset + b.checks, end)
            break
    # (the clock first: a stops on it; the result may be larger than the pipe holds)
    shared[1] = _NO_PATH if at_b is None else at_b
    return pickle.dumps((at_b, end if at_b is not None else None, b.checks))


def _child_setup(parent: int) -> None:
    """The child dies with its parent, and the application's signal handlers stay the
    parent's (the parent kills the child on its own interrupt)."""
    for sig in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP):
        signal.signal(sig, signal.SIG_DFL)
    try:
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    except (OSError, AttributeError):
        pass
    if os.getppid() != parent:  # the parent died before the prctl
        os._exit(0)


def _read_until(inp, until: float) -> bytes | None:
    """Everything the child writes, None if it has not closed the pipe by ``until``."""
    chunks = []
    fd = inp.fileno()
    while True:
        wait = until - time.perf_counter()
        if wait <= 0:
            return None
        if not select.select([fd], [], [], min(wait, 60.0))[0]:
            continue
        chunk = os.read(fd, 1 << 16)
        if not chunk:
            return b"".join(chunks)
        chunks.append(chunk)


def _kill(pid: int) -> None:
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def _wait(pid: int) -> None:
    try:
        os.waitpid(pid, 0)
    except ChildProcessError:
        pass


def _finish_alone(a):
    log.debug("the first search goes on alone")
    end = None
    while end is None:
        end = a.step(None)
    return end
