"""Stand-in for the ``rclcpp`` module that MTC's ROS 2 Python scripts import.

``mtc`` needs no ROS node: ``init()`` and ``shutdown()`` do nothing, and a :class:`Node` only
carries its name. Where a ROS 2 script passes its node (``task.loadRobotModel(node)``,
``core.PipelinePlanner(node, "ompl", "RRTConnectkConfigDefault")``), ``mtc`` accepts and ignores
it, so ``import rclcpp`` becomes ``from mtc import rclcpp`` and the script runs unchanged.
"""

from __future__ import annotations

__all__ = ["Node", "init", "ok", "shutdown"]


def init(*args, **kwargs) -> None:
    """Accepted and ignored (``rclcpp.init()``)."""


def shutdown(*args, **kwargs) -> None:
    """Accepted and ignored (``rclcpp.shutdown()``)."""


def ok() -> bool:
    """Always True: there is no ROS context to shut down."""
    return True


class Node:
    """A ROS 2 node stand-in: ``Node(name)`` keeps the name, nothing runs."""

    def __init__(self, name: str, *args, **kwargs):
        if not isinstance(name, str):
            raise TypeError(f"Node(name): the name must be a str, not {type(name).__name__}")
        self._name = name

    def get_name(self) -> str:
        return self._name

    def __repr__(self) -> str:
        return f"rclcpp.Node({self._name!r})"
