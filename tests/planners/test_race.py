"""Tests of mtc.planners._race: two searches raced by their state checks, with the same winner
side by side in two processes as in turns in one."""

from __future__ import annotations

import logging
import os
import sys

import pytest

from mtc.planners import _race

FORK = pytest.mark.skipif(not (sys.platform.startswith("linux") and hasattr(os, "fork")),
                          reason="the side-by-side race forks (Linux only)")
MODES = [pytest.param(False, id="in-turns"), pytest.param(True, id="forked", marks=FORK)]


class Search:
    """A scripted search: each check is one step of a counter; turns of ``turn`` checks; it
    ends with a path at ``found`` checks, or without one at ``fails`` checks."""

    def __init__(self, name, found=None, fails=None, turn=7):
        self.name, self.found, self.fails, self.turn = name, found, fails, turn
        self.checks = 0
        self.halted = False

    def step(self, halt):
        for _ in range(self.turn):
            if halt is not None and halt():
                self.halted = True
                return None
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
    won, end, b_checks = _race.race(first, second, offset, parallel=parallel)
    assert won == winner
    assert end[2] == ("a", "b")[winner]
    assert (end[0] is None) == (end[1] != "")
    assert b_checks >= 1


@pytest.mark.parametrize("parallel", MODES)
def test_the_loser_stops_once_it_cannot_win(parallel):
    """Neither search runs on to its own end (here: hours of checks) once the other has ended
    first."""
    endless = 10**10
    first, second = Search("a", fails=endless, turn=50), Search("b", found=300, turn=50)
    first.checks = 100
    won, end, b_checks = _race.race(first, second, 100, parallel=parallel)
    assert won == 1 and end[0] == "path of b" and b_checks == 300
    assert first.halted
    if not parallel:  # turn by turn: a stops at the first check past b's end
        assert first.checks == 100 + 300 + 1
    first, second = Search("a", found=400, turn=50), Search("b", fails=endless, turn=50)
    first.checks = 100
    won, end, b_checks = _race.race(first, second, 100, parallel=parallel)
    assert won == 0 and end[0] == "path of a"
    assert 0 < b_checks < endless
    if not parallel:
        assert b_checks == 400 - 100


def test_in_turns_the_search_behind_goes_next():
    log = []

    class Logged(Search):
        def step(self, halt):
            log.append((self.name, self.checks))
            return super().step(halt)

    first, second = Logged("a", found=40, turn=10), Logged("b", found=1000, turn=10)
    first.checks = 15
    won, _, _ = _race.race(first, second, 15, parallel=False)
    assert won == 0
    # a at 15 and b at 15 + 0: a first (a tie); then always the one whose clock is behind; a
    # ends at 40 in its turn from 35, b goes on only until its clock reaches 40
    assert log == [("a", 15), ("b", 0), ("a", 25), ("b", 10), ("a", 35), ("b", 20)]
    assert second.checks == 40 - 15 and second.halted


@FORK
def test_a_dead_child_leaves_the_first_search_to_finish(caplog):
    class Crashing(Search):
        def step(self, halt):
            raise RuntimeError("boom")

    first = Search("a", found=60, turn=7)
    with caplog.at_level(logging.WARNING, logger=_race.__name__):
        won, end, b_checks = _race.race(first, Crashing("b"), 0, parallel=True)
    assert won == 0 and end[0] == "path of a" and b_checks == 0
    assert "second search's process ended without a result" in caplog.text


def test_can_fork_is_off_when_switched_off_or_with_other_threads(monkeypatch):
    monkeypatch.setattr(_race, "PARALLEL", False)
    assert not _race.can_fork()
    monkeypatch.setattr(_race, "PARALLEL", True)
    monkeypatch.setattr(_race.threading, "active_count", lambda: 2)
    assert not _race.can_fork()
