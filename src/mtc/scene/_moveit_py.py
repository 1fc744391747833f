"""moveit_py's keyword names for the scene classes' parameters.

api.md gives ``mtc``'s methods short parameter names (``state``, ``group``, ``link``); moveit_py
spells them ``robot_state``, ``joint_model_group_name``, ``link_name``, ... . Scripts written
for moveit_py pass those names, so the methods accept them as well.
"""

from __future__ import annotations

import functools


def moveit_py_keywords(**aliases: str):
    """Let a method also take moveit_py's keyword names: ``alias=own_name`` pairs."""

    def wrap(fn):
        @functools.wraps(fn)
        def method(*args, **kwargs):
            for alias, own in aliases.items() if kwargs else ():
                if alias in kwargs:
                    if own in kwargs:
                        raise TypeError(f"{fn.__name__}() got both {own!r} and moveit_py's name for it, {alias!r}")
                    kwargs[own] = kwargs.pop(alias)
            return fn(*args, **kwargs)

        return method

    return wrap
