"""Bundled robot descriptions.

``panda()`` is the Franka Emika Panda from ``example-robot-data`` with an SRDF in MoveIt's
``panda_moveit_config`` naming (groups ``panda_arm``, ``hand``, ``panda_arm_hand``; named
states ``ready``, ``extended``, ``transport``, ``open``, ``close``; end effector ``hand``).
"""

from __future__ import annotations

import os
from functools import lru_cache

from mtc.scene.robot_model import DescriptionError, RobotModel, default_package_dirs

__all__ = ["panda", "panda_urdf_path", "PANDA_SRDF"]

PANDA_SRDF = os.path.join(os.path.dirname(__file__), "panda.srdf")

#: Acceleration limits of MoveIt's panda_moveit_config joint_limits.yaml [rad/s^2].
PANDA_JOINT_LIMITS = {
    "panda_joint1": {"max_acceleration": 3.75},
    "panda_joint2": {"max_acceleration": 1.875},
    "panda_joint3": {"max_acceleration": 2.5},
    "panda_joint4": {"max_acceleration": 3.125},
    "panda_joint5": {"max_acceleration": 3.75},
    "panda_joint6": {"max_acceleration": 5.0},
    "panda_joint7": {"max_acceleration": 5.0},
    "panda_finger_joint1": {"max_acceleration": 1.0},
    "panda_finger_joint2": {"max_acceleration": 1.0},
}


def panda_urdf_path() -> str:
    """Path of the Panda URDF inside the ``example-robot-data`` install.

    Raises:
        DescriptionError: ``example-robot-data`` is not installed.
    """
    for share in default_package_dirs():
        path = os.path.join(share, "example-robot-data", "robots", "panda_description", "urdf", "panda.urdf")
        if os.path.isfile(path):
            return path
    raise DescriptionError(
        "the Panda URDF of example-robot-data was not found; install it with "
        "'pip install example-robot-data'"
    )


@lru_cache(maxsize=1)
def panda() -> RobotModel:
    """The Franka Emika Panda (loaded once per process; the model is read-only)."""
    return RobotModel(panda_urdf_path(), PANDA_SRDF, joint_limits=PANDA_JOINT_LIMITS)
