"""Load the bundled Panda, print its groups, named states and end effector, and check a box
against the hand.

The first thing to run on a new machine: it shows that the robot description, kinematics and
collision checking work. Run: ``python examples/panda_scene.py``
"""

from __future__ import annotations

import mtc
from mtc import msgs


def main() -> None:
    robot = mtc.robots.panda()
    print(f"robot '{robot.name}', planning frame '{robot.model_frame}'")
    for name in robot.joint_model_group_names:
        group = robot.get_joint_model_group(name)
        states = ", ".join(robot.group_state_names(name)) or "-"
        print(f"  group {name:15s} joints: {', '.join(group.variable_names)}")
        print(f"  {'':21s} named states: {states}")
    for name in robot.end_effectors:
        eef = robot.get_end_effector(name)
        print(f"  end effector '{name}': group '{eef.group}' on link '{eef.parent_link}' of '{eef.parent_group}'")

    scene = mtc.current_scene(robot)  # arm at 'ready', hand 'open', empty world
    tcp = scene.current_state.get_global_link_transform("panda_hand_tcp")
    box = msgs.PoseStamped(header=msgs.Header(frame_id="world"))
    box.pose.position = msgs.Point(x=tcp[0, 3], y=tcp[1, 3], z=tcp[2, 3])
    interface = mtc.PlanningSceneInterface()
    interface.add_box("box", box, size=(0.12, 0.12, 0.04))
    print(f"box through the hand: colliding = {scene.is_state_colliding()}, pairs = {scene.get_collisions()}")
    box.pose.position.z += 0.5
    interface.add_box("box", box, size=(0.12, 0.12, 0.04))
    print(f"box 0.5 m higher:     colliding = {scene.is_state_colliding()}, "
          f"distance = {scene.distance_to_collision():.3f} m")


if __name__ == "__main__":
    main()
