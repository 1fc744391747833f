"""Tests of mtc.planners._race: two searches raced by their state checks, with the same winner
side by side in two processes as in turns in one."""

from __future__ import annotations

import logging
import os
import random
import signal
import sys
import time

import pytest

from mtc.planners import _race

FORK = pytest.mark.skipif(not (sys.platform.startswith("linux") and hasattr(os, "fork")),
                          reason="the side-by-side race forks (Linux only)")
MODES = [pytest.param(False, id="in-turns"), pytest.param(True, id="forked", marks=FORK)]
ENDLESS = 10**10


def _deadline(seconds: float = 30.0) -> float:
    return time.perf_counter() + seconds


class Search:
    """A scripted search: each check is one step of a counter, ``halt`` is asked every
    ``grain`` checks (OMPL asks between iterations), turns of ``turn`` checks; it ends with a
    path at ``found`` checks, or without one at ``fails`` checks."""

    def __init__(self, name, found=None, fails=None, turn=7, grain=1):
        self.name, self.found, self.fails, self.turn, self.grain = name, found, fails, turn, grain
        self.checks = 0
        self.halted = False

    def step(self, halt):
        limit = self.checks + self.turn
        while self.checks < limit:
            if halt is not None and halt():
                self.halted = True
                return None
            for _ in range(self.grain):
                self.checks += 1
                if self.checks == self.found:
                    return (f"path of {self.name}", "", self.name)
                if self.checks == self.fails:
                    return (None, f"{self.name} failed", self.name)
        return None


@pytest.mark.parametrize("parallel", MODES)
@pytest.mark.parametrize(
    "a, b, offset, winner",
    [
        ((100, None), (40, None), 50, 1),  # b ends at 90 on a's clock
        ((100, None), (50, None), 50, 0),  # a tie goes to the first search
        ((100, None), (51, None), 50, 0),
        ((None, 30), (500, None), 20, 1),  # a fails early; b is run to its end
        ((None, 30), (None, 40), 20, 0),  # both fail: the first one's failure
        ((100, None), (None, 10), 50, 0),
    ],
)
def test_the_search_that_ends_first_on_the_first_ones_clock_wins(parallel, a, b, offset, winner):
    first, second = Search("a", *a), Search("b", *b)
    first.checks = offset  # the first search made these checks before the race
    won, end, checks = _race.race(first, second, offset, _deadline(), parallel=parallel)
    assert won == winner
    assert end[2] == ("a", "b")[winner]
    assert (end[0] is None) == (end[1] != "")
    # both searches' checks up to the winner's end (the loser's only up to there)
    ends = [x[0] or x[1] for x in (a, b)]
    clock = (ends[0], offset + ends[1])[winner] if end[0] is not None else ENDLESS
    assert checks == min(ends[0], clock) + min(offset + ends[1], clock) - offset


@pytest.mark.parametrize("parallel", MODES)
def test_the_loser_stops_once_it_cannot_win(parallel):
    """Neither search runs on to its own end (here: hours of checks) once the other has ended
    first."""
    first, second = Search("a", fails=ENDLESS, turn=50), Search("b", found=300, turn=50)
    first.checks = 100
    won, end, checks = _race.race(first, second, 100, _deadline(), parallel=parallel)
    assert won == 1 and end[0] == "path of b" and checks == 400 + 300
    if parallel:
        # a stops within a stretch (asked to halt) or between two (not stepped again): which of
        # the two depends on when the child's end reaches it; either way long before its own end
        assert first.checks < ENDLESS // 1000
    else:  # turn by turn: a is halted at the first check past b's end
        assert first.halted and first.checks == 100 + 300 + 1
    first, second = Search("a", found=400, turn=50), Search("b", fails=ENDLESS, turn=50)
    first.checks = 100
    won, end, checks = _race.race(first, second, 100, _deadline(), parallel=parallel)
    assert won == 0 and end[0] == "path of a" and checks == 400 + 300
    if not parallel:
        assert second.checks == 400 - 100


def test_in_turns_the_search_behind_goes_next():
    log = []

    class Logged(Search):
        def step(self, halt):
            log.append((self.name, self.checks))
            return super().step(halt)

    first, second = Logged("a", found=40, turn=10), Logged("b", found=1000, turn=10)
    first.checks = 15
    won, _, _ = _race.race(first, second, 15, _deadline(), parallel=False)
    assert won == 0
    # a at 15 and b at 15 + 0: a first (a tie); then always the one whose clock is behind; a
    # ends at 40 in its turn from 35, b goes on only until its clock reaches 40
    assert log == [("a", 15), ("b", 0), ("a", 25), ("b", 10), ("a", 35), ("b", 20)]
    assert second.checks == 40 - 15 and second.halted


@FORK
def test_random_races_have_the_ideal_winner_in_both_modes():
    """Scripted searches with random ends, turn sizes and halt grains: forked and in turns give
    the search with the smaller end clock (ties to the first), and the same check count."""
    rng = random.Random(5)
    for _ in range(40):
        offset = rng.randint(0, 60)
        spec = [(offset + rng.randint(1, 400), rng.random() < 0.8), (rng.randint(1, 400), rng.random() < 0.8)]
        turns, grains = [rng.randint(1, 60) for _ in "ab"], [rng.randint(1, 9) for _ in "ab"]
        at = [n if found else _race._NO_PATH for n, found in spec]
        at[1] = at[1] + offset if spec[1][1] else at[1]
        ideal = 0 if at[0] <= at[1] else 1
        got = []
        for parallel in (False, True):
            a, b = (Search(name, *((n, None) if found else (None, n)), turn=t, grain=g)
                    for name, (n, found), t, g in zip("ab", spec, turns, grains))
            a.checks = offset
            won, end, checks = _race.race(a, b, offset, _deadline(), parallel=parallel)
            got.append((won, end, checks))
        assert got[0] == got[1] and got[0][0] == ideal, (spec, offset, turns, grains, got)


@FORK
def test_the_shared_clocks_are_never_read_half_written():
    """The parent polls the child's clock while the child writes it (and the other way): a read
    sees the old value or the new one, never a mix (a torn 0 would stop a search at once)."""
    for trial in range(40):
        clocks = _race._shared_clocks()
        pid = os.fork()
        if pid == 0:
            time.sleep(0.0002 * (trial % 5))
            clocks[1] = 826
            os._exit(0)
        seen = set()
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < 0.003:
            seen.add(clocks[1])
        os.waitpid(pid, 0)
        assert seen <= {_race._NOT_DONE, 826}


@FORK
def test_an_error_in_the_forked_search_reaches_the_caller():
    class Broken(Search):
        def step(self, halt):
            raise ValueError("broken second search")

    with pytest.raises(RuntimeError, match="(?s)second search failed in its process.*ValueError: broken second"):
        _race.race(Search("a", fails=ENDLESS), Broken("b"), 0, _deadline(), parallel=True)
    with pytest.raises(ValueError, match="broken second search"):  # in turns: the error itself
        _race.race(Search("a", found=10**6), Broken("b"), 0, _deadline(), parallel=False)


@FORK
def test_a_child_killed_leaves_the_first_search_to_finish(caplog):
    class Killed(Search):
        def step(self, halt):
            os.kill(os.getpid(), signal.SIGKILL)

    first = Search("a", found=60, turn=7)
    with caplog.at_level(logging.WARNING, logger=_race.__name__):
        won, end, checks = _race.race(first, Killed("b"), 0, _deadline(), parallel=True)
    assert won == 0 and end[0] == "path of a" and checks == 60
    assert "second search's process ended without a result" in caplog.text


@FORK
def test_a_stuck_child_is_killed_after_the_deadline(caplog):
    class Stuck(Search):
        def step(self, halt):
            time.sleep(60)

    t0 = time.perf_counter()
    with caplog.at_level(logging.WARNING, logger=_race.__name__):
        won, end, _ = _race.race(Search("a", found=60), Stuck("b"), 0, _deadline(0.2), parallel=True)
    assert won == 0 and end[0] == "path of a"
    assert time.perf_counter() - t0 < 0.2 + _race._GRACE + 2.0


@FORK
def test_where_fork_fails_the_two_take_turns(monkeypatch, caplog):
    def no_fork():
        raise BlockingIOError(11, "Resource temporarily unavailable")

    monkeypatch.setattr(_race.os, "fork", no_fork)
    fds = len(os.listdir("/proc/self/fd"))
    with caplog.at_level(logging.WARNING, logger=_race.__name__):
        got = _race.race(Search("a", found=100), Search("b", found=40), 50, _deadline(), parallel=True)
    assert got == (1, ("path of b", "", "b"), (50 + 40) + 40)  # a up to b's end, and b
    assert "could not fork the second search" in caplog.text
    assert len(os.listdir("/proc/self/fd")) == fds


@FORK
def test_a_far_deadline_is_waited_for_in_pieces():
    """select() cannot wait 1e10 s at once: the parent waits in pieces."""
    got = _race.race(Search("a", found=100), Search("b", found=40), 50, _deadline(1e10), parallel=True)
    assert got[0] == 1


@FORK
def test_no_descriptor_is_left_open_when_the_first_search_raises():
    class Raising(Search):
        def step(self, halt):
            raise KeyError("first search")

    fds = len(os.listdir("/proc/self/fd"))
    for _ in range(5):
        with pytest.raises(KeyError):
            _race.race(Raising("a"), Search("b", fails=ENDLESS), 0, _deadline(), parallel=True)
    assert len(os.listdir("/proc/self/fd")) == fds


def test_can_fork_is_off_when_switched_off_or_where_the_child_could_not_be_managed(monkeypatch):
    monkeypatch.setattr(_race, "PARALLEL", True)
    monkeypatch.setenv("MTC_PARALLEL_SEARCH", "0")  # read at each race
    assert not _race.can_fork()
    monkeypatch.delenv("MTC_PARALLEL_SEARCH")
    monkeypatch.setattr(_race, "PARALLEL", False)
    assert not _race.can_fork()
    monkeypatch.setattr(_race, "PARALLEL", True)
    monkeypatch.setattr(_race.threading, "active_count", lambda: 2)
    assert not _race.can_fork()
    monkeypatch.setattr(_race.threading, "active_count", lambda: 1)
    if hasattr(signal, "SIGCHLD"):
        old = signal.signal(signal.SIGCHLD, signal.SIG_IGN)
        try:
            assert not _race.can_fork()
        finally:
            signal.signal(signal.SIGCHLD, old)
