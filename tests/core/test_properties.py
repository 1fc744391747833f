"""Property and PropertyMap (mtc_semantics.md §4), ported from MTC's test_properties.cpp and test_mtc.py."""

from __future__ import annotations

import pytest
from mockups import ForwardMockup, GeneratorMockup, add

from mtc import core, msgs
from mtc.core import Property, PropertyError, PropertyMap
from mtc.core.properties import PropertyTypeError, UndeclaredPropertyError, UndefinedPropertyError, unsigned_int

PARENT = core.Stage.PropertyInitializerSource.PARENT
INTERFACE = core.Stage.PropertyInitializerSource.INTERFACE


def test_standard():
    props = PropertyMap()
    props.declare("double1", 1.0, "first")
    props.declare("double2", 2, type=float)
    props.declare("double4", type=float)
    assert props.get("double1") == 1.0
    assert props.get("double2") == 2.0 and isinstance(props.get("double2"), float)
    with pytest.raises(UndeclaredPropertyError):
        props.get("double3")
    with pytest.raises(UndefinedPropertyError):
        props.get("double4")
    assert not props.property("double4").defined()
    assert props.get("double4", 0.0) == 0.0
    props.set("double3", 3.0)
    assert props.get("double3") == 3.0


def test_error_types_and_texts():
    props = PropertyMap()
    props.declare("d", type=float)
    with pytest.raises(UndeclaredPropertyError) as e:
        props.get("x")
    assert str(e.value) == "Property 'x': undeclared"
    assert isinstance(e.value, KeyError) and isinstance(e.value, RuntimeError)
    with pytest.raises(UndefinedPropertyError) as e:
        props.get("d")
    assert str(e.value) == "Property 'd': undefined"
    with pytest.raises(PropertyTypeError) as e:
        props.set("d", "text")
    assert str(e.value) == "Property 'd': type str doesn't match property's declared type float"
    assert isinstance(e.value, TypeError) and isinstance(e.value, PropertyError)
    with pytest.raises(UndeclaredPropertyError, match="trying to set undeclared property 'y' with NULL value"):
        props.set("y", None)


def test_directset():
    props = PropertyMap()
    props.set("int1", 1)
    assert props.get("int1") == 1
    assert props.property("int1").serialize() == "1"


def test_redeclare():
    props = PropertyMap()
    props.declare("double1", type=float)
    props.declare("double1", type=float)  # same type: fine
    with pytest.raises(PropertyTypeError):
        props.declare("double1", type=str)
    # ints are accepted for float properties (MTC Appendix A #12), text is not
    props.set("double1", 1)
    assert props.get("double1") == 1.0
    with pytest.raises(PropertyTypeError):
        props.set("double1", "1")
    props.set("double1", 3.14)
    assert props.get("double1") == 3.14


def test_bool_is_not_a_number():
    props = PropertyMap()
    props.declare("n", type=int)
    props.declare("b", type=bool)
    with pytest.raises(TypeError):
        props.set("n", True)
    with pytest.raises(TypeError):
        props.set("b", 1)
    props.set("b", False)
    assert props["b"] is False


def test_reset():
    props = PropertyMap()
    props.declare("double1", type=float)
    # setCurrent() only assigns temporary values
    props.setCurrent("double1", 1.0)
    assert props.get("double1") == 1.0
    assert props.property("double1").defaultValue() is None
    props.reset()
    assert not props.property("double1").defined()
    # set() also updates the default
    props.set("double1", 1.0)
    assert props.property("double1").defaultValue() == 1.0
    props.setCurrent("double1", 2.0)
    assert props.get("double1") == 2.0
    assert props.property("double1").defaultValue() == 1.0
    props.reset()
    assert props.get("double1") == 1.0


def test_anytype():
    props = PropertyMap()
    props.declare("any", description="store any type")
    props.set("any", 1)
    assert props.get("any") == 1
    props.set("any", "foo")
    assert props.get("any") == "foo"


def test_serialize():
    props = PropertyMap()
    props.declare("int", type=int)
    assert props.property("int").serialize() == ""
    props.set("int", 42)
    assert props.property("int").serialize() == "42"


def test_unsigned():
    props = PropertyMap()
    props.declare("n", 1, type=unsigned_int)
    props.set("n", 3)
    with pytest.raises(TypeError, match="unsigned int"):
        props.set("n", -1)


@pytest.fixture
def master_slave():
    master = PropertyMap()
    master.declare("double1", 1.0)
    master.declare("double2", 2.0)
    master.declare("double4", 4.0)
    slave = PropertyMap()
    slave.declare("double1", type=float)
    slave.declare("double2", type=float)
    slave.declare("double3", type=float)
    return master, slave


def test_init_from_standard(master_slave):
    master, slave = master_slave
    slave.configureInitFrom(PARENT)  # init all matching vars
    assert not slave.property("double1").defined()
    slave.performInitFrom(PARENT, master)
    assert slave.get("double1") == 1.0
    assert slave.get("double2") == 2.0
    assert not slave.property("double3").defined()
    with pytest.raises(UndeclaredPropertyError):
        slave.property("double4")


def test_init_from_limited(master_slave):
    master, slave = master_slave
    slave.configureInitFrom(PARENT, ["double1"])  # limit init to listed props
    slave.performInitFrom(PARENT, master)
    assert slave.get("double1") == 1.0
    assert not slave.property("double2").defined()


def test_init_from_single_name_is_one_name(master_slave):
    """A str is one property name, not a list of characters (Appendix A #6)."""
    master, slave = master_slave
    slave.configureInitFrom(PARENT, "double2")
    slave.performInitFrom(PARENT, master)
    assert not slave.property("double1").defined()
    assert slave.get("double2") == 2.0


def test_init_from_source_id(master_slave):
    master, slave = master_slave
    slave.configureInitFrom(PARENT)
    slave.performInitFrom(INTERFACE, master)  # wrong source: no effect
    assert not slave.property("double1").defined()


def test_init_from_multiple_source_ids(master_slave):
    _, slave = master_slave
    slave.configureInitFrom(PARENT)
    slave.configureInitFrom(PARENT)  # allowed a second time with the same source
    with pytest.raises(RuntimeError, match="already configured for initialization from another source id"):
        slave.configureInitFrom(INTERFACE)


def test_init_from_other_name(master_slave):
    master, slave = master_slave
    slave.property("double1").configureInitFrom(PARENT, "double2")
    slave.performInitFrom(PARENT, master)
    assert slave.get("double1") == 2.0
    assert not slave.property("double2").defined()


def test_init_from_function(master_slave):
    master, slave = master_slave
    slave.property("double3").configureInitFrom(PARENT, lambda other: other.get("double1") + other.get("double2"))
    slave.performInitFrom(PARENT, master)
    assert slave.get("double3") == 3.0


def test_init_priority_parent_before_interface():
    """A value inherited from PARENT is not overwritten from INTERFACE; a manual value wins over both."""
    parent = PropertyMap({"x": 1.0})
    iface = PropertyMap({"x": 2.0})
    p = PropertyMap()
    p.declare("x", type=float).configureInitFrom(PARENT | INTERFACE, "x")
    p.performInitFrom(PARENT, parent)
    p.performInitFrom(INTERFACE, iface)
    assert p["x"] == 1.0
    q = PropertyMap()
    q.declare("x", type=float).configureInitFrom(PARENT | INTERFACE, "x")
    q.performInitFrom(PARENT, PropertyMap({"y": 0.0}))  # undeclared in parent: skipped
    q.performInitFrom(INTERFACE, iface)
    assert q["x"] == 2.0
    q.set("x", 5.0)
    q.performInitFrom(PARENT, parent)
    assert q["x"] == 5.0


def test_init_type_mismatch_names_property():
    p = PropertyMap()
    p.declare("x", type=float).configureInitFrom(PARENT, "x")
    with pytest.raises(PropertyTypeError, match="Property 'x': type str"):
        p.performInitFrom(PARENT, PropertyMap({"x": "text"}))


# --- Python binding surface (test_mtc.py) -----------------------------------------------


@pytest.mark.parametrize("name,value", [
    ("double", 3.14), ("long", 42), ("long", 13), ("bool", True), ("bool", False), ("string", "anything"),
])
def test_assign(name, value):
    props = PropertyMap()
    props[name] = value
    assert props[name] == value


def test_iter_items_update_bool():
    props = PropertyMap()
    assert not props  # MTC's binding says True for an empty map (Appendix A #4)
    props["double"] = 3.14
    props["bool"] = True
    keys = list(props)
    assert keys == ["bool", "double"]
    assert [k for k, _ in props.items()] == keys
    assert isinstance(props.items()[0][1], Property)
    props.update({"double": 2.72, "bool": False})
    props.update({})
    assert props["double"] == 2.72 and props["bool"] is False
    assert props
    assert "bool" in props and "nothing" not in props
    with pytest.raises(RuntimeError):
        props["nothing"]


def test_expose():
    props = PropertyMap()
    props["double"] = 3.14
    other = PropertyMap()
    props.exposeTo(other, "double")
    assert other["double"] == props["double"]
    props.exposeTo(other, "double", "float")
    assert other["float"] == props["double"]
    props["a"] = 1
    props.exposeTo(other, ["a"])
    assert other["a"] == 1
    # only the type, description and default are exposed, not temporary values
    props.setCurrent("a", 7)
    third = PropertyMap()
    props.exposeTo(third, "a")
    assert third["a"] == 1


def test_property_object():
    p = Property()
    p.setDescription("Foo Property")
    p.setValue("Bar")
    assert p.defined()
    assert (p.value(), p.defaultValue(), p.description()) == ("Bar", "Bar", "Foo Property")
    p.setCurrentValue("Baz")
    p.reset()  # setValue() values are persistent
    assert p.value() == "Bar"


# --- typed attributes on stages ---------------------------------------------------------


def test_stage_typed_attributes():
    stage = GeneratorMockup()
    stage.timeout = 5  # int for a float property
    assert stage.timeout == 5.0 and isinstance(stage.timeout, float)
    assert stage.properties["timeout"] == 5.0
    stage.setTimeout(1.23)
    assert stage.timeout == 1.23
    for bad in ("string", [], {}, set(), None):
        with pytest.raises(TypeError):
            stage.timeout = bad
    assert stage.marker_ns == stage.name
    stage.marker_ns = "ns"
    assert stage.properties["marker_ns"] == "ns"
    with pytest.raises(UndefinedPropertyError):
        GeneratorMockup().timeout  # noqa: B018


def test_forwarded_properties_attribute():
    stage = GeneratorMockup()
    stage.forwarded_properties = ["name1", "name2", "name3"]
    assert stage.forwarded_properties == ["name1", "name2", "name3"]
    stage.forwarded_properties = "name"  # one name (Appendix A #6)
    assert stage.forwarded_properties == ["name"]
    with pytest.raises(TypeError, match="Expecting a string or a list of strings"):
        stage.forwarded_properties = [1, 2]


def test_plain_attributes_unaffected():
    stage = GeneratorMockup()
    stage.my_value = 3  # not a property: an ordinary attribute
    assert stage.my_value == 3
    assert "my_value" not in stage.properties
    with pytest.raises(AttributeError):
        stage.nothing  # noqa: B018


def test_property_declared_later_is_an_attribute_of_that_instance_only():
    """A property declared on one instance reads and writes as its attribute; another
    instance of the same class keeps an ordinary attribute of that name."""
    declaring, plain = GeneratorMockup(), GeneratorMockup()
    plain.late_value = "plain"  # before the name is a property anywhere
    declaring.properties.declare("late_value", 1.5, "declared after construction")
    assert declaring.late_value == 1.5
    declaring.late_value = 2
    assert declaring.properties["late_value"] == 2.0
    with pytest.raises(TypeError):
        declaring.late_value = "text"
    assert declaring.properties["late_value"] == 2.0  # (a rejected value changes nothing)
    assert plain.late_value == "plain"
    plain.late_value = [1]
    assert plain.late_value == [1] and "late_value" not in plain.properties
    del plain.late_value
    with pytest.raises(AttributeError, match="has no attribute 'late_value'"):
        plain.late_value  # noqa: B018
    with pytest.raises(AttributeError, match="has no attribute 'late_value'"):
        GeneratorMockup().late_value  # noqa: B018


def test_class_attributes_and_private_names_are_never_properties():
    class WithClassValue(GeneratorMockup):
        shadowed = "class value"

        def method(self):
            return "method"

    stage = WithClassValue()
    for name in ("shadowed", "method", "_private"):
        stage.properties.declare(name, 1.0)
    assert stage.shadowed == "class value"
    assert stage.method() == "method"
    with pytest.raises(AttributeError):
        stage._private  # noqa: B018
    stage.shadowed = "instance value"  # an ordinary attribute, the property is untouched
    assert stage.shadowed == "instance value" and stage.properties["shadowed"] == 1.0


# --- inheritance in a task -------------------------------------------------------------------


class NeedsGroup(ForwardMockup):
    def __init__(self):
        super().__init__()
        self.properties.declare("group", type=str).configureInitFrom(PARENT)

    def computeForward(self, from_state):
        self.properties.get("group")  # fails at compute time if undefined
        super().computeForward(from_state)


def test_parent_inheritance(t):
    """A child inherits a property set on the task (the root container)."""
    add(t, GeneratorMockup())
    fwd = add(t, NeedsGroup())
    t.setProperty("group", "arm")
    assert t.plan()
    assert fwd.properties["group"] == "arm"


def test_undefined_property_at_compute_names_the_chain(t):
    """An undefined property raised in compute() says where it is (un)declared up the tree."""
    add(t, GeneratorMockup())
    inner = add(t, core.SerialContainer("pick"))
    add(inner, NeedsGroup())
    with pytest.raises(RuntimeError) as info:
        t.plan()
    assert str(info.value) == (
        "Property 'group': undefined\n"
        "in stage 'FWD1': declared, but undefined, inherits from parent\n"
        "in stage 'pick': undeclared\n"
        "in stage 'task pipeline': undeclared"
    )


def test_inheritance_type_error_becomes_init_error(t):
    add(t, GeneratorMockup())
    add(t, NeedsGroup())
    t.setProperty("group", 3)
    with pytest.raises(core.InitStageError) as info:
        t.plan()
    assert "FWD1: Property 'group': type int doesn't match property's declared type str" in str(info.value)
    assert "in stage 'task pipeline': defined here" in str(info.value)


def test_unknown_attribute_of_a_library_class_raises():
    """As MTC's bound C++ classes: setting a name that is neither a property nor an attribute
    of one of mtc's own stages or planners raises AttributeError (a typo would set nothing)."""
    from mtc import stages

    ik = stages.ComputeIK("ik", stages.GeneratePose("pose"))
    with pytest.raises(AttributeError, match=r"'ComputeIK' object has no attribute 'max_ik_solution' \(its properties: .*max_ik_solutions"):
        ik.max_ik_solution = 8
    assert ik.max_ik_solutions == 1
    ik.max_ik_solutions = 8  # the real name still works
    assert ik.max_ik_solutions == 8
    planner = core.PipelinePlanner()
    with pytest.raises(AttributeError, match="'PipelinePlanner' object has no attribute 'planner_id'"):
        planner.planner_id = "PRMkConfigDefault"
    with pytest.raises(AttributeError, match="'CartesianPath' object has no attribute 'jump_threshold'"):
        core.CartesianPath().jump_threshold = 0.0
    with pytest.raises(AttributeError, match="'Task' object has no attribute 'max_solutions'"):
        core.Task().max_solutions = 3


def test_a_property_declared_on_one_library_instance_leaves_typos_on_others_errors():
    """setProperty on one of mtc's stages makes the name an attribute of that stage only: on
    another instance of the class, setting it still raises (a typo there would set nothing)."""
    from mtc import stages

    a = stages.MoveTo("a", core.JointInterpolationPlanner())
    b = stages.MoveTo("b", core.JointInterpolationPlanner())
    a.setProperty("max_tries", 5)
    assert a.max_tries == 5
    with pytest.raises(AttributeError, match=r"'MoveTo' object has no attribute 'max_tries' \(its properties: "):
        b.max_tries = 3
    with pytest.raises(AttributeError, match="has no attribute 'max_tries'"):
        b.max_tries  # noqa: B018
    assert "max_tries" not in b.properties and "max_tries" not in vars(b)


def test_user_subclasses_keep_attributes_of_their_own():
    """A Python subclass (as in MTC, whose Python subclasses have a __dict__) sets any attribute."""

    class Counter(core.Generator):
        def __init__(self):
            super().__init__("counter")
            self.calls = 0

        def canCompute(self):
            return False

        def compute(self):
            self.calls += 1

    c = Counter()
    c.extra = "mine"
    assert (c.calls, c.extra) == (0, "mine")
    c.timeout = 2.0  # a property still type-checks
    with pytest.raises(TypeError):
        c.timeout = "long"


@pytest.mark.parametrize("value", [object(), [1.0], {"a": 1.0}, {"a"}, (1, 2), msgs.MotionPlanRequest()])
def test_dictionary_api_takes_the_types_mtc_converts(value):
    """MTC's binding converts bool, numbers, strings and registered messages only; anything else
    given through map[key] = v or update() raises TypeError, and update() sets nothing then."""
    props = PropertyMap()
    with pytest.raises(TypeError, match="no conversion available"):
        props["x"] = value
    with pytest.raises(TypeError, match="no conversion available"):
        props.update({"ok": 1.0, "x": value})
    assert "ok" not in props and "x" not in props
    for i, fine in enumerate((True, 3, 2.5, "s", msgs.PoseStamped())):
        props[f"y{i}"] = fine
        assert props[f"y{i}"] == fine
    # a property declared with a type takes any value of it, also through the dictionary
    props.declare("f", None, type=frozenset)
    props["f"] = frozenset({"a"})
    assert props["f"] == frozenset({"a"})


def test_keyword_names_of_mtcs_binding():
    """MTC's binding names: configureInitFrom(sources, names), exposeTo(other, name[, other_name])
    and exposeTo(other, names), property(key), Property.setDescription(desc)."""
    props, other = PropertyMap(), PropertyMap()
    props.declare("x", 1.0)
    props.declare("y", 2.0)
    props.configureInitFrom(sources=PARENT, names=["x"])
    assert props.property(key="x").initsFrom(PARENT) and not props.property("y").initsFrom(PARENT)
    props.exposeTo(other=other, name="x")
    props.exposeTo(other=other, name="x", other_name="z")
    props.exposeTo(other, names=["y"])
    assert list(other) == ["x", "y", "z"]
    with pytest.raises(TypeError, match="once"):
        props.exposeTo(other, "x", name="x")
    p = Property()
    p.setDescription(desc="d")
    assert p.description() == "d"


def test_message_values_are_copied_when_set_and_read():
    """As MTC's bindings (a Python value becomes a C++ value when set, and a new Python object
    when read): reusing or editing a message after passing it to a stage does not change the
    stage's setting, and neither does editing a value read back."""
    from mtc import msgs, stages

    twist = msgs.TwistStamped(header=msgs.Header(frame_id="world"))
    twist.twist.linear.z = 0.05
    up = stages.MoveRelative("up", core.JointInterpolationPlanner())
    up.setDirection(twist)
    twist.twist.linear.z = -0.05
    down = stages.MoveRelative("down", core.JointInterpolationPlanner())
    down.properties["direction"] = twist
    assert up.properties["direction"].twist.linear.z == 0.05
    assert down.properties["direction"].twist.linear.z == -0.05

    pose = msgs.PoseStamped(header=msgs.Header(frame_id="world"))
    gen = stages.GeneratePose("pose")
    gen.pose = pose
    pose.pose.position.z = 0.3
    assert gen.pose.pose.position.z == 0.0
    gen.pose.pose.position.z = 9.0  # edits a copy
    gen.properties["pose"].pose.position.x = 9.0
    assert gen.pose.pose.position.z == 0.0 and gen.properties.get("pose").pose.position.x == 0.0

    names = ["a"]
    p = PropertyMap()
    p.declare("names", type=list)
    p.set("names", names)
    names.append("b")
    assert p["names"] == ["a"]
    planner = core.JointInterpolationPlanner()
    p.declare("planner")
    p.set("planner", planner)
    assert p["planner"] is planner  # objects, not data, are shared (as MTC's shared pointers)


def test_property_names_are_strings_and_map_calls_are_all_or_nothing():
    """A property name that is not a non-empty str is refused before anything is declared
    (it broke iteration, planning and introspection later); configureInitFrom, exposeTo and
    update check every name before changing any."""
    pm = PropertyMap()
    for call in (lambda: pm.set(None, 1), lambda: pm.declare(5), lambda: pm.update({7: 4}),
                 lambda: pm.__setitem__(1, 2), lambda: pm.set("", 1)):
        with pytest.raises(TypeError, match="a property name must be a non-empty str"):
            call()
    assert len(pm) == 0
    with pytest.raises(TypeError, match="update\\(\\) takes a dict of property values, not list"):
        pm.update([("a", 1)])
    stage = GeneratorMockup()
    before = stage.properties.keys()
    with pytest.raises(TypeError, match="a property name must be a non-empty str, got 3"):
        stage.properties[3] = 1
    with pytest.raises(TypeError, match="a property name must be a non-empty str, got 1"):
        stage.setProperty(1, 2)
    assert stage.properties.keys() == before
    # configureInitFrom: a conflict on a later property leaves the earlier ones as they were
    pm = PropertyMap({"a": 1, "c": 2})
    pm.property("c").configureInitFrom(core.Stage.INTERFACE)
    with pytest.raises(PropertyError, match="Property 'c': Property was already configured"):
        pm.configureInitFrom(core.Stage.PARENT)
    assert not pm.property("a").initsFrom(core.Stage.PARENT)
    with pytest.raises(TypeError, match="a property name must be a non-empty str, got 5"):
        pm.configureInitFrom(core.Stage.PARENT, [5])
    # exposeTo: an undeclared or conflicting name later in the list exposes nothing
    dst = PropertyMap({"c": "text"})
    with pytest.raises(UndeclaredPropertyError, match="nope"):
        pm.exposeTo(dst, ["a", "nope"])
    with pytest.raises(PropertyTypeError):
        pm.exposeTo(dst, ["a", "c"])  # c is an int here, a str there
    assert dst.keys() == ["c"]
