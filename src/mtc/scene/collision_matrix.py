"""MoveIt's allowed collision matrix (ACM): which pairs of bodies may touch.

An explicit entry for a pair wins; without one, the *default entries* of the two bodies decide
(``set_default_entry(name, True)``: "this body may touch anything"), and where both bodies have
one, a forbidding default wins, as in MoveIt 1. Bodies are links, world objects and attached
objects, by name.
"""

from __future__ import annotations

from collections.abc import Iterable

from mtc import msgs

__all__ = ["AllowedCollisionMatrix", "name_list"]


def name_list(names, what: str, none: bool = True) -> list[str]:
    """Names given as one name or a list of them (or, with ``none``, None for no names), as a
    list.

    Raises:
        TypeError: anything else, or an item that is not a str (``what`` names the argument).
    """
    if none and names is None:
        return []
    if isinstance(names, str):
        return [names]
    if isinstance(names, Iterable):
        out = list(names)
        for n in out:
            if not isinstance(n, str):
                raise TypeError(f"{what} must be a name or a list of names, got {n!r} in {names!r}")
        return out
    raise TypeError(f"{what} must be a name or a list of names, got {names!r}")


class AllowedCollisionMatrix:
    """Allowed collisions between named bodies.

    Every change renews ``token`` (and bumps ``version``); copies carry the token over, so two
    matrices with the same token have the same content and can share a collision set-up.
    """

    __slots__ = ("_entries", "_defaults", "version", "token")

    def __init__(self, allowed_pairs: Iterable[tuple[str, str]] = ()):
        self._entries: dict[frozenset, bool] = {}
        self._defaults: dict[str, bool] = {}
        self.version = 0
        self.token = object()
        for a, b in allowed_pairs:
            if b == "*":
                self._defaults[a] = True
            else:
                self._entries[frozenset((a, b))] = True

    def copy(self) -> AllowedCollisionMatrix:
        other = AllowedCollisionMatrix()
        other._entries = dict(self._entries)
        other._defaults = dict(self._defaults)
        other.version = self.version
        other.token = self.token
        return other

    def clear(self) -> None:
        """Remove every entry and default entry (MoveIt's ``clear``): afterwards every pair is
        checked, the SRDF's disabled pairs included."""
        self._entries.clear()
        self._defaults.clear()
        self._changed()

    def _changed(self) -> None:
        self.version += 1
        self.token = object()

    def set_entry(self, first, second=None, allowed: bool | None = None) -> None:
        """Allow (True) or forbid (False) collisions between ``first`` and ``second``.

        Each of ``first``/``second`` is a name or a list of names (all pairs are set).
        ``set_entry(name, allowed)`` sets every existing entry of ``name``.
        """
        if allowed is None and (msgs.is_bool(second) or msgs.is_number(second)):
            second, allowed = None, second
        allowed = msgs.flag(allowed, "allowed")  # (a number reads as a bool, as pybind11's caster reads it)
        firsts = name_list(first, "first", none=False)
        if second is None:
            for name in firsts:
                for key in [k for k in self._entries if name in k]:
                    self._entries[key] = allowed
        else:
            for a in firsts:
                for b in name_list(second, "second", none=False):
                    self._entries[frozenset((a, b))] = allowed
        self._changed()

    def remove_entry(self, first: str, second: str | None = None) -> None:
        """Drop the explicit entry of a pair, or every entry of ``first``."""
        if second is None:
            self.forget_pairs([first])
            self._defaults.pop(first, None)
        else:
            self._entries.pop(frozenset((first, second)), None)
        self._changed()

    def forget_pairs(self, names) -> None:
        """Drop every explicit pair entry of ``names`` (their default entries stay): what MoveIt
        does for a collision object it removes from the world."""
        names = set(names)
        stale = [k for k in self._entries if k & names]
        if stale:
            for key in stale:
                del self._entries[key]
            self._changed()

    def get_entry(self, first: str, second: str) -> bool:
        """Whether ``first`` and ``second`` may collide (explicit entry, else defaults)."""
        entry = self._entries.get(frozenset((first, second)))
        if entry is not None:
            return entry
        # as MoveIt 1 (MTC master): without an explicit entry the default entries decide; with
        # defaults for both bodies, a forbidding one wins
        defaults = [d for d in (self._defaults.get(first), self._defaults.get(second)) if d is not None]
        return bool(defaults) and all(defaults)

    def has_entry(self, first: str, second: str) -> bool:
        return frozenset((first, second)) in self._entries

    def set_default_entry(self, name: str, allowed: bool) -> None:
        """Allow (True) or stop allowing (False) collisions of ``name`` with anything that has
        no explicit entry with it."""
        allowed = msgs.flag(allowed, "allowed")
        self._defaults[name] = allowed
        self._changed()

    def get_default_entry(self, name: str) -> bool:
        return self._defaults.get(name, False)

    @property
    def entry_names(self) -> list[str]:
        names = {n for key in self._entries for n in key} | set(self._defaults)
        return sorted(names)

    def to_msg(self) -> msgs.AllowedCollisionMatrix:
        """As a ``msgs.AllowedCollisionMatrix`` (square matrix over ``entry_names``)."""
        names = self.entry_names
        entries = [
            msgs.AllowedCollisionEntry(enabled=[self.get_entry(a, b) if a != b else False for b in names])
            for a in names
        ]
        return msgs.AllowedCollisionMatrix(
            entry_names=names,
            entry_values=entries,
            default_entry_names=sorted(self._defaults),
            default_entry_values=[self._defaults[n] for n in sorted(self._defaults)],
        )

    def __repr__(self) -> str:
        allowed = sum(self._entries.values())
        return f"AllowedCollisionMatrix({allowed} allowed pairs, {len(self._entries)} entries)"
