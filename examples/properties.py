"""Properties and property maps: MTC's properties tutorial.

As MTC's ``demo/scripts/properties.py``: create a ``Property`` with a description and a value,
fill a ``PropertyMap`` from a dict, read values and ``Property`` objects back, iterate over a
map, expose some of its properties to a second map, and reach a stage's own map through
``stage.properties``. At the end the stage plans in a small task, so that ``--view`` has
something to show. Expected outcome: the printed values below, and 1 solution.
Run: ``python examples/properties.py [--view]``
"""

from __future__ import annotations

import argparse

import mtc
from mtc import core, stages
from mtc.msgs import PoseStamped


def property_tutorial() -> tuple[core.PropertyMap, core.PropertyMap, core.Stage]:
    """The tutorial's steps; returns the two maps and the stage for inspection."""
    # a property with a description and a value
    p = core.Property()
    p.setDescription("Foo Property")
    p.setValue("Bar")
    assert p.defined()
    print(p.value())
    print(p.defaultValue())
    print(p.description())

    # a property map, filled from a dict: values of arbitrary types
    pm = core.PropertyMap()
    props = {"prop1": "test", "prop2": 21, "prop3": PoseStamped(), "prop4": 5.4}
    pm.update(props)
    pm["prop5"] = 2  # a new property, declared on first assignment

    # a value, or the whole Property object
    print(pm["prop5"])
    p2 = pm.property("prop5")
    print(p2.value())

    print("\n")
    for name in pm:
        print(name, "\t\t", pm[name])
    print("\n")

    # copy (expose) a subset of the properties into another map
    pm2 = core.PropertyMap()
    pm.exposeTo(pm2, ["prop2", "prop4"])
    for name in pm2:
        print(name, "\t\t", pm2[name])
    print("\n")

    # every stage has its own property map
    stage = stages.CurrentState("Current State")
    stage_props = stage.properties
    print("stage properties:", ", ".join(sorted(stage_props)))
    return pm, pm2, stage


def main(argv: list[str] | None = None) -> core.Task:
    """Run the tutorial, then plan its stage headless; ``--view`` shows it in a browser."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--view", action="store_true", help="show the solution in a meshcat viewer")
    args = parser.parse_args(argv)

    viewer = None
    if args.view:
        from mtc.viewer import Viewer

        viewer = Viewer(mtc.robots.panda())
        print("viewer at", viewer.url)

    _, _, stage = property_tutorial()
    task = core.Task()
    task.name = "properties"
    task.add(stage)
    result = task.plan()
    task.printState()
    if not result:
        task.explainFailure()  # which stages failed, and why
    print(f"plan: {result}, {len(task.solutions)} solution(s), costs:",
          [round(s.cost, 4) for s in task.solutions])
    if viewer is not None and task.solutions:
        task.publish(task.solutions[0])
        viewer.hold()
    return task


if __name__ == "__main__":
    main()
