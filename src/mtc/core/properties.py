"""Properties: typed, inheritable configuration values of stages and planners.

A :class:`Property` holds a declared type, a description, a *default* and a *current*
value and, optionally, an initializer that fills it from another :class:`PropertyMap`
(the parent stage's map or an interface state's map). This follows MTC's
``properties.h`` (``mtc_semantics.md`` §4.1, §4.2) including its error texts; the Python
binding quirks of Appendix A are fixed (``bool(PropertyMap)``, int for float properties).

Types are Python types, a tuple of types, ``None`` (any type) or a :class:`PropertyType`
such as :data:`unsigned_int`. ``None`` is the *empty* value: a property whose current
value is ``None`` is not ``defined()``.
"""

from __future__ import annotations

import copy
import math
import numbers
from collections.abc import Callable, Iterable, Mapping
from enum import Enum, Flag, IntEnum, IntFlag
from typing import Any

import numpy as np

from mtc import msgs

__all__ = [
    "Property",
    "PropertyError",
    "PropertyInitializerSource",
    "PropertyMap",
    "PropertyType",
    "PropertyTypeError",
    "TypedPropertyAccess",
    "UndeclaredPropertyError",
    "UndefinedPropertyError",
    "unsigned_int",
]



def non_negative(name: str) -> Callable[[Any], Any]:
    """A property converter: a number must be >= 0 (infinity allowed, NaN not); other values
    are left to the type check.

    Raises (when the property is set):
        ValueError: naming the property.
    """

    def convert(value):
        if msgs.is_number(value) and not value >= 0:
            raise ValueError(f"{name} must be a number >= 0, got {value!r}")
        return value

    return convert


def positive(name: str) -> Callable[[Any], Any]:
    """A property converter: a number must be finite and > 0 (see :func:`non_negative`)."""

    def convert(value):
        if msgs.is_number(value) and not (value > 0 and math.isfinite(value)):
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
        return value

    return convert


def finite(name: str, hint: str = "") -> Callable[[Any], Any]:
    """A property converter: a number must be finite (``hint`` says what a value means)."""

    def convert(value):
        if msgs.is_number(value) and not math.isfinite(value):
            raise ValueError(f"{name} must be a finite number{hint}, got {value!r}")
        return value

    return convert


def fraction(name: str) -> Callable[[Any], Any]:
    """A property converter: a number must lie in [0, 1] (NaN does not)."""

    def convert(value):
        if msgs.is_number(value) and not 0.0 <= value <= 1.0:
            raise ValueError(f"{name} must be a number in [0, 1], got {value!r}")
        return value

    return convert


def valid_message(name: str) -> Callable[[Any], Any]:
    """A property converter: a message must hold its declared field types and finite numbers
    (:func:`mtc.msgs.validate`), so a NaN pose is refused when set, not when planning."""

    def convert(value):
        if isinstance(value, msgs._Message):
            msgs.validate(value, name)
        return value

    return convert


def _not_none(value, what: str) -> None:
    """MTC's binding has no C++ value for None: assigning it raises TypeError."""
    if value is None:
        raise TypeError(f"{what}: None is not a property value (give a value of the property's type)")


def _convertible(value, what: str) -> None:
    """A value given through MTC's dictionary-style API (``map[key] = value``, ``update()``)
    for a property of no declared type must be of a type MTC's binding converts: bool, a
    number, a string or a registered message (``msgs.MotionPlanRequest`` is not one). Anything
    else raises TypeError, as there. A property declared with a type takes any value of that
    type (beyond MTC, whose binding cannot pass e.g. a planner through the dictionary)."""
    if isinstance(value, (bool, numbers.Real, str)):
        return
    if isinstance(value, msgs._Message) and getattr(type(value), "_PROPERTY_TYPE", True):
        return
    raise TypeError(
        f"{what}: no conversion available for property type {_value_type_name(value)} "
        "(allowed: bool, int, float, str or a message of mtc.msgs other than MotionPlanRequest; "
        "use the stage's attribute or PropertyMap.set() for other declared types)"
    )


class BindingEnum(IntEnum):
    """An IntEnum that prints as pybind11 prints MTC's enums: ``str()`` and ``format()`` give
    ``'MergeMode.WAYPOINTS'`` (Python 3.11's IntEnum gives ``'1'``); ``int()``, comparisons and
    arithmetic stay those of the number."""

    __str__ = Enum.__str__


class PropertyInitializerSource(IntFlag):
    """Where a property may be initialized from (MTC's ``Stage::PropertyInitializerSource``)."""

    __str__ = Flag.__str__  # (as BindingEnum's)

    DEFAULT = 0
    MANUAL = 1
    PARENT = 2
    INTERFACE = 4


def _check_property_name(name) -> None:
    """Property names are non-empty strings (MTC's are ``std::string``)."""
    if not isinstance(name, str) or not name:
        raise TypeError(f"a property name must be a non-empty str, got {name!r}")


def _source(value) -> int:
    """An initializer source: PropertyInitializerSource flags (PARENT, INTERFACE, OR-ed).

    Raises:
        TypeError: not an integer flag; ValueError: unknown bits.
    """
    if not msgs.is_number(value, integral=True):
        raise TypeError(
            "the source must be Stage.PropertyInitializerSource.PARENT or INTERFACE (or both OR-ed), "
            f"got {value!r}"
        )
    value = int(value)
    if value & ~int(PropertyInitializerSource.MANUAL | PropertyInitializerSource.PARENT
                    | PropertyInitializerSource.INTERFACE):  # (a negative value has such bits)
        raise ValueError(f"unknown initializer source {value} (PARENT=2, INTERFACE=4, or both OR-ed)")
    return value


# initialized_from values: 0 = set() (manual, persistent), 1 = setCurrent() (manual, temporary),
# 2 = PARENT, 4 = INTERFACE, _NEVER = not initialized
_SET_VALUE = 0
_SET_CURRENT = 1
_NEVER = 1 << 30


class PropertyError(RuntimeError):
    """Base of all property errors (MTC's ``Property::error``, a ``runtime_error``).

    Attributes:
        name: The property concerned, or "" when unknown.
    """

    def __init__(self, msg: str, name: str = ""):
        super().__init__(msg)
        self.msg = msg
        self.name = name

    def setName(self, name: str) -> None:
        """Attach the property name (the message then starts with ``Property '<name>'``)."""
        self.name = name

    def __str__(self) -> str:
        if self.name:
            return f"Property '{self.name}': {self.msg}"
        return f"Property: {self.msg}"


class UndeclaredPropertyError(PropertyError, KeyError):
    """The property is not declared in the map (MTC's ``Property::undeclared``)."""

    def __init__(self, name: str, msg: str = "undeclared"):
        super().__init__(msg, name)

    __str__ = PropertyError.__str__


class UndefinedPropertyError(PropertyError):
    """The property has neither a current nor a default value (MTC's ``Property::undefined``)."""

    def __init__(self, name: str, msg: str = "undefined"):
        super().__init__(msg, name)


class PropertyTypeError(PropertyError, TypeError):
    """A value does not match the property's declared type (MTC's ``Property::type_error``)."""

    def __init__(self, current_type: str, declared_type: str, name: str = ""):
        super().__init__(f"type {current_type} doesn't match property's declared type {declared_type}", name)
        self.current_type = current_type
        self.declared_type = declared_type


class PropertyType:
    """A property type given by a name and a checking/converting function.

    Args:
        name: Type name shown in errors and introspection.
        convert: ``convert(value) -> value``; raises ``TypeError`` or ``ValueError`` if
            ``value`` is not acceptable, else returns the (possibly converted) value.
    """

    def __init__(self, name: str, convert: Callable[[Any], Any]):
        self.name = name
        self.convert = convert

    def __repr__(self) -> str:
        return f"PropertyType({self.name})"


def _to_unsigned(value):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(type(value).__name__)
    if value < 0:
        raise ValueError(f"negative value {value}")
    return int(value)


#: Non-negative int (C++ ``unsigned int``/``size_t`` properties such as ``max_ik_solutions``).
unsigned_int = PropertyType("unsigned int", _to_unsigned)


def _type_name(t) -> str:
    if t is None:
        return "any"
    if isinstance(t, PropertyType):
        return t.name
    if isinstance(t, tuple):
        return " or ".join(_type_name(x) for x in t)
    return getattr(t, "__name__", str(t))


def _normalize_type(t):
    if t is None or isinstance(t, PropertyType):
        return t
    if isinstance(t, type):
        return t
    if isinstance(t, tuple) and t and all(isinstance(x, type) for x in t):
        return t
    raise TypeError(f"property type must be a type, a tuple of types, a PropertyType or None, got {t!r}")


def _coerce(value, declared):
    """Return ``value`` converted to the declared type, or raise PropertyTypeError."""
    if value is None or declared is None:
        return value
    if isinstance(declared, PropertyType):
        try:
            return declared.convert(value)
        except (TypeError, ValueError):
            raise PropertyTypeError(_value_type_name(value), declared.name) from None
    types = declared if isinstance(declared, tuple) else (declared,)
    if bool in types and isinstance(value, np.bool_):
        return bool(value)  # (as pybind11's bool caster)
    is_bool = isinstance(value, bool)
    for t in types:
        # bool is an int in Python, but not a number for a numeric property (as pybind's casters)
        if is_bool and t is not bool and t in (int, float):
            continue
        if isinstance(value, t):
            return value
    if not is_bool:
        # ints are accepted for float properties (MTC Appendix A #12), numpy scalars for both
        if float in types and isinstance(value, numbers.Real):
            return float(value)
        if int in types and isinstance(value, numbers.Integral):
            return int(value)
        if set in types and isinstance(value, frozenset):
            return set(value)
        if isinstance(value, str) and msgs.PoseStamped in types:
            return msgs.identity_pose_stamped(value)  # as MTC's message casters
    raise PropertyTypeError(_value_type_name(value), _type_name(declared))


def _is_data(value) -> bool:
    """Whether ``value`` is plain data: messages, numbers, strings, arrays and containers of
    them (no stages, planners, scenes or callables, which are shared as MTC shares pointers)."""
    if isinstance(value, np.ndarray):
        return value.dtype != object  # (an array of objects holds them as a list does)
    if value is None or isinstance(value, (msgs._Message, str, bytes, numbers.Number)):
        return True
    if isinstance(value, (list, tuple, set, frozenset)):
        return all(_is_data(v) for v in value)
    if isinstance(value, dict):
        return all(_is_data(k) and _is_data(v) for k, v in value.items())
    return False


def _owned(value):
    """``value`` as a property keeps or hands it out: a copy where it is mutable data, as MTC's
    bindings convert a Python value to a C++ one when it is set and back when it is read, so
    that editing a message after passing it to a stage (or reusing it for another stage), or
    editing a value read back, does not change the stage's setting."""
    if isinstance(value, (msgs._Message, list, dict, set, np.ndarray)) and _is_data(value):
        return copy.deepcopy(value)
    return value


def _value_type_name(value) -> str:
    kind = type(value)
    # numpy's scalars by their full names: "numpy.bool", not a "bool" that is not allowed
    return f"numpy.{kind.__name__}" if kind.__module__ == "numpy" else kind.__name__


class Property:
    """One property: declared type, description, default and current value.

    Args:
        type: Declared type (a type, tuple of types, :class:`PropertyType`) or None for any.
        description: Human readable description.
        default: Default value (None: no default).
        convert: Optional ``convert(value) -> value`` applied to every assigned non-None
            value before the type check (e.g. to accept a link name for a PoseStamped).
    """

    __slots__ = (
        "_type",
        "_description",
        "_default",
        "_value",
        "_initializer",
        "_source_flags",
        "_initialized_from",
        "_convert",
        "_name",
    )

    def __init__(self, type=None, description: str = "", default=None, convert=None):
        self._name = ""
        self._type = _normalize_type(type)
        self._description = description
        self._convert = convert
        self._default = None
        self._value = None
        self._initializer = None
        self._source_flags = 0
        self._initialized_from = _NEVER
        if default is not None:
            self._default = self._check(default)

    # --- internal helpers -------------------------------------------------------------
    def _check(self, value):
        if value is None:
            return None
        if self._convert is not None:
            value = self._convert(value)
        return _owned(_coerce(value, self._type))

    def _copy(self) -> "Property":
        p = Property.__new__(Property)
        p._type = self._type
        p._description = self._description
        p._default = self._default
        p._value = self._value
        p._initializer = self._initializer
        p._source_flags = self._source_flags
        p._initialized_from = self._initialized_from
        p._convert = self._convert
        p._name = self._name
        return p

    # --- MTC API ----------------------------------------------------------------------
    def setValue(self, value) -> None:
        """Set current *and* default value; survives :meth:`reset` (a manual, persistent value).

        Raises:
            TypeError: ``value`` is None (as MTC's binding: None has no C++ value), or the
                property has no declared type and ``value`` is not of a type MTC's binding
                converts (as ``map[key] = value``).
        """
        self._check_assignable(value, "Property.setValue")
        self._setValue(value)

    def _check_assignable(self, value, what: str) -> None:
        _not_none(value, what)
        if self._type is None:
            _convertible(value, what)

    def _setValue(self, value) -> None:
        # (PropertyMap.set, as C++'s set(name, boost::any()), may make a property undefined)
        value = self._check(value)
        self._value = value
        self._default = value
        self._initialized_from = _SET_VALUE

    def _append(self, item) -> None:
        """Append ``item`` (checked and copied as a one-item list) to the list this property
        holds as a manual value, in place: one copy per call where ``set`` would copy the
        whole list (a stage's ``addPose`` called for many poses)."""
        if self._initialized_from == _SET_VALUE and isinstance(self._value, list):
            self._value.extend(self._check([item]))
        else:
            self._setValue([*(self.value() or []), item])

    def setCurrentValue(self, value) -> None:
        """Set the current value only; :meth:`reset` drops it again.

        Raises:
            TypeError: as :meth:`setValue`.
        """
        self._check_assignable(value, "Property.setCurrentValue")
        self._setCurrent(value)

    def _setCurrent(self, value) -> None:
        # (inheritance may set a property empty: None is allowed here)
        self._value = self._check(value)
        self._initialized_from = _SET_CURRENT

    def setDefaultValue(self, value) -> None:
        """Set the default value (the current value is untouched)."""
        self._default = self._check(value)

    def value(self):
        """Current value if set, else the default (None if neither)."""
        return self._value if self._value is not None else self._default

    def defaultValue(self):
        """The default value (None if none)."""
        return self._default

    def reset(self) -> None:
        """Drop temporary and inherited values; a value given with :meth:`setValue` stays."""
        if self._initialized_from == _SET_VALUE:
            return
        self._value = None
        self._initialized_from = _NEVER

    def defined(self) -> bool:
        """True iff the *current* value is set (a default alone does not count, as in MTC)."""
        return self._value is not None

    def description(self) -> str:
        """The description."""
        return self._description

    def setDescription(self, desc: str) -> None:
        """Change the description (the keyword name is MTC's binding's)."""
        self._description = desc

    def typeName(self) -> str:
        """Name of the declared type, or of the value's type for an untyped property."""
        if self._type is None:
            v = self.value()
            return "any" if v is None else _value_type_name(v)
        return _type_name(self._type)

    def declaredType(self):
        """The declared type (None: any)."""
        return self._type

    def serialize(self) -> str:
        """String form of the value ("" if it has none), as MTC's introspection shows it: as a
        C++ stream writes it (numbers with 6 significant digits, bools as 1/0)."""
        v = self.value()
        if v is None:
            return ""
        if isinstance(v, bool):
            return "1" if v else "0"
        if isinstance(v, float):
            return f"{v:g}"
        return str(v)

    def initsFrom(self, source: int) -> bool:
        """Whether the property is configured to initialize from ``source``."""
        return bool(self._source_flags & int(source))

    def configureInitFrom(
        self, source: int, initializer: str | Callable[["PropertyMap"], Any] | None = None
    ) -> "Property":
        """Configure initialization from ``source`` (PARENT, INTERFACE or both OR-ed).

        Args:
            source: Source flags.
            initializer: Name of the property to read from the other map (default: this
                property's own name in its map), or a function ``f(other_map) -> value``.

        Raises:
            PropertyError: Already configured for another source.
        """
        source = _source(source)
        self._check_init_source(source)
        if initializer is None:
            if not self._name:
                raise TypeError("configureInitFrom() needs the name of the property to read from")
            initializer = self._name
        if isinstance(initializer, str):
            other_name = initializer
            self._initializer = lambda other: other._raw(other_name)
        elif callable(initializer):
            self._initializer = initializer
        else:
            raise TypeError(f"initializer must be a property name or a callable, got {initializer!r}")
        self._source_flags = source
        return self

    def _check_init_source(self, source: int) -> None:
        if self._initializer is not None and self._source_flags != source:
            error = PropertyError("Property was already configured for initialization from another source id")
            error.setName(self._name)
            raise error

    def __repr__(self) -> str:
        return f"Property({self.typeName()}, value={self.value()!r})"


class PropertyMap:
    """Properties by name, iterated in name order (MTC's ``PropertyMap``)."""

    __slots__ = ("_props", "_owner_type")

    def __init__(self, values: dict | None = None):
        self._props: dict[str, Property] = {}
        # the class whose instances read this map's properties as attributes (see
        # TypedPropertyAccess): a declared name becomes an attribute of that class
        self._owner_type: type | None = None
        if values:
            self.update(values)

    # --- declaration and access -------------------------------------------------------
    _INFER = object()

    def _check_redeclaration(self, name: str, type) -> Property | None:
        """The property ``name`` declared already (None if not), which a declaration of type
        ``type`` must match, as in MTC, unless the first one was "any"."""
        existing = self._props.get(name)
        if existing is not None and existing._type is not None and existing._type != type:
            raise PropertyTypeError(_type_name(type), _type_name(existing._type), name)
        return existing

    def declare(self, name: str, default=None, description: str = "", type=_INFER, convert=None) -> Property:
        """Declare a property (or return the existing one of the same type).

        Args:
            name: Property name.
            default: Default value (None: undefined until set).
            description: Description.
            type: Declared type; by default the default value's type, or any if there is
                no default.
            convert: Optional conversion applied before type checks.

        Raises:
            PropertyTypeError: ``name`` exists with a different declared type.
        """
        _check_property_name(name)
        if type is PropertyMap._INFER:
            type = None if default is None else default.__class__
        type = _normalize_type(type)
        existing = self._check_redeclaration(name, type)
        if existing is not None:
            return existing
        p = Property(type, description, None, convert)
        p._name = name
        try:
            p._default = p._check(default)
        except PropertyError as e:
            e.setName(name)
            raise
        self._props[name] = p
        if self._owner_type is not None:
            _install_attribute(self._owner_type, name)
        return p

    def hasProperty(self, name: str) -> bool:
        """Whether ``name`` is declared."""
        return name in self._props

    def property(self, key: str) -> Property:
        """The :class:`Property` object of ``key`` (the keyword name is MTC's binding's).

        Raises:
            UndeclaredPropertyError: ``key`` is not declared.
        """
        try:
            return self._props[key]
        except KeyError:
            raise UndeclaredPropertyError(key) from None

    def set(self, name: str, value) -> None:
        """Set a persistent value, declaring the property with the value's type if needed."""
        _check_property_name(name)
        p = self._props.get(name)
        if p is None:
            if value is None:
                raise UndeclaredPropertyError(name, f"trying to set undeclared property '{name}' with NULL value")
            p = self.declare(name, type=value.__class__)
        try:
            p._setValue(value)
        except PropertyError as e:
            e.setName(name)
            raise

    def setCurrent(self, name: str, value) -> None:
        """Set a temporary value (dropped by :meth:`reset`)."""
        p = self.property(name)
        _not_none(value, f"setCurrent() of property '{name}'")
        try:
            p._setCurrent(value)  # (as set(): the map's own setters take any value)
        except PropertyError as e:
            e.setName(name)
            raise

    def _raw(self, name: str):
        """Value (current or default, None if empty); raises UndeclaredPropertyError."""
        p = self._props.get(name)
        if p is None:
            raise UndeclaredPropertyError(name)
        return p.value()

    _NO_FALLBACK = object()

    def get(self, name: str, fallback=_NO_FALLBACK):
        """The value of ``name`` (current, else default).

        Args:
            name: Property name.
            fallback: Returned when the property has no value.

        Raises:
            UndeclaredPropertyError: ``name`` is not declared.
            UndefinedPropertyError: No value and no fallback given.
        """
        value = self._raw(name)
        if value is None:
            if fallback is PropertyMap._NO_FALLBACK:
                raise UndefinedPropertyError(name)
            return fallback
        return value

    def countDefined(self, names: Iterable[str]) -> int:
        """Number of ``names`` that have a value (defaults count, as in MTC)."""
        return sum(1 for n in names if self._raw(n) is not None)

    def reset(self) -> None:
        """:meth:`Property.reset` every property."""
        for p in self._props.values():
            p.reset()

    def copy(self) -> "PropertyMap":
        """An independent copy (properties are copied, values are shared)."""
        m = PropertyMap.__new__(PropertyMap)
        m._props = {k: p._copy() for k, p in self._props.items()}
        m._owner_type = None
        return m

    # --- initialization ---------------------------------------------------------------
    def configureInitFrom(self, sources: int, names: str | Iterable[str] | None = None) -> None:
        """Initialize the listed (default: all) declared properties from ``sources``.

        Undeclared names are ignored, as in MTC. A single ``str`` is one name. (The keyword
        names are those of MTC's binding.)
        """
        sources = _source(sources)
        if isinstance(names, str):
            names = [names]
        if names is not None:
            try:
                names = list(names)
            except TypeError:
                raise TypeError(f"configureInitFrom() takes a property name or a list of names, got {names!r}") from None
            for name in names:
                _check_property_name(name)
        wanted = None if names is None else set(names)
        # an empty list means all properties (MTC's default argument {})
        chosen = [(name, p) for name, p in self._props.items() if not wanted or name in wanted]
        for _name, p in chosen:  # (all are checked before the first is changed)
            p._check_init_source(sources)
        for name, p in chosen:
            p.configureInitFrom(sources, name)

    def performInitFrom(self, source: int, other: "PropertyMap") -> None:
        """Initialize properties configured for ``source`` from ``other``.

        A value from a higher-priority source (manual < PARENT < INTERFACE by number)
        is kept; an undeclared name in ``other`` skips the property; an undefined one
        sets it empty (so a later, lower-priority source may still fill it).

        Raises:
            PropertyTypeError: An inherited value has the wrong type.
        """
        source = int(source)
        for name, p in self._props.items():
            if p._initialized_from < source and p._value is not None:
                continue
            if not (p._source_flags & source):
                continue
            try:
                value = p._initializer(other)
            except UndeclaredPropertyError:
                continue
            except UndefinedPropertyError:
                value = None
            try:
                p._setCurrent(value)
            except PropertyError as e:
                e.setName(name)
                raise
            p._initialized_from = source

    def exposeTo(
        self,
        other: "PropertyMap",
        names: str | Iterable[str] | None = None,
        other_name: str | None = None,
        *,
        name: str | None = None,
    ) -> None:
        """Declare properties in ``other`` with the same type, description and default.

        Args:
            other: Target map.
            names: One name or a list of names (MTC's binding: ``name`` for one, ``names``
                for a list; both keywords are taken).
            other_name: Name in ``other`` (only with a single name).
        """
        if not isinstance(other, PropertyMap):
            raise TypeError(f"exposeTo() exposes to another PropertyMap (e.g. stage.properties), not {type(other).__name__}")
        if (names is None) == (name is None):
            raise TypeError("exposeTo() takes the property name(s) once: exposeTo(other, name_or_names)")
        if name is not None:
            names = name
        if isinstance(names, str):
            pairs = [(names, other_name or names)]
        else:
            if other_name is not None:
                raise TypeError("other_name is only allowed when exposing a single property")
            pairs = [(n, n) for n in names]
        exposed = []
        for name, target in pairs:  # (all are checked before the first is declared)
            _check_property_name(target)
            p = self.property(name)
            other._check_redeclaration(target, p._type)
            exposed.append((p, target))
        for p, target in exposed:
            # as MTC: an existing declaration in other is kept as it is
            other.declare(target, p._default, p._description, type=p._type, convert=p._convert)

    # --- Python mapping protocol ------------------------------------------------------
    def __getitem__(self, name: str):
        return _owned(self._raw(name))

    def __setitem__(self, name: str, value) -> None:
        _not_none(value, f"properties['{name}'] = ...")
        self._check_convertible(name, value, f"properties['{name}'] = ...")
        self.set(name, value)

    def _check_convertible(self, name: str, value, what: str) -> None:
        p = self._props.get(name)
        if p is None or p._type is None:
            _convertible(value, what)

    def __contains__(self, name) -> bool:
        return name in self._props

    def __iter__(self):
        return iter(sorted(self._props))

    def __len__(self) -> int:
        return len(self._props)

    def __bool__(self) -> bool:
        # MTC's binding returns True for an *empty* map (Appendix A #4); mtc fixes it
        return bool(self._props)

    def keys(self):
        """Property names in name order."""
        return sorted(self._props)

    def items(self):
        """``(name, Property)`` pairs in name order (the Property object, as MTC's binding)."""
        return [(k, self._props[k]) for k in sorted(self._props)]

    def update(self, values: dict) -> None:
        """``set()`` every item of ``values`` (none of them may be None: then nothing is set)."""
        if not isinstance(values, Mapping):
            raise TypeError(f"update() takes a dict of property values, not {type(values).__name__}")
        for k, v in values.items():
            _check_property_name(k)
            _not_none(v, f"update() of property '{k}'")
            self._check_convertible(k, v, f"update() of property '{k}'")
            p = self._props.get(k)
            if p is not None:  # (all values are checked before the first is set)
                try:
                    p._check(v)
                except PropertyError as e:
                    e.setName(k)
                    raise
        for k, v in values.items():
            self.set(k, v)

    def __repr__(self) -> str:
        return "PropertyMap({" + ", ".join(f"{k!r}: {self._props[k].value()!r}" for k in sorted(self._props)) + "})"


class TypedPropertyAccess:
    """Mixin: declared properties read and written as attributes (``stage.timeout = 5``).

    The instance keeps its map in ``self._properties``, made by :meth:`_newProperties`.
    Reading an attribute that is a declared property returns its value (an undefined one
    raises :class:`UndefinedPropertyError`); writing one type-checks it (``TypeError`` on
    mismatch). Names starting with ``_`` and names defined on the class are never treated
    as properties.

    A declared name becomes a data descriptor of the instance's class (:class:`_PropertyAttribute`)
    rather than being resolved by ``__getattr__``/``__setattr__``: with those hooks on the
    class, every attribute access of every stage would take Python's slow generic path.
    """

    # property name -> function(value) -> attribute value (e.g. sets shown as sorted lists)
    _attribute_getters: dict = {}
    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.__module__.split(".", 1)[0] != "mtc" and "__setattr__" not in cls.__dict__:
            # a user's Python subclass may keep attributes of its own (as Python subclasses of
            # MTC's bound classes can), and pays nothing for the check
            cls.__setattr__ = object.__setattr__

    def __setattr__(self, name: str, value) -> None:
        """Setting an unknown public attribute of one of mtc's own classes raises
        ``AttributeError``, as MTC's bound C++ classes do (a typo such as
        ``stage.max_ik_solution = 8`` would otherwise set nothing)."""
        if name[0] != "_" and not hasattr(type(self), name):
            raise self._no_attribute(name)
        object.__setattr__(self, name, value)

    def _no_attribute(self, name: str) -> AttributeError:
        props = self.__dict__.get("_properties")
        known = sorted(props._props) if props is not None else []
        return AttributeError(
            f"'{type(self).__name__}' object has no attribute '{name}'"
            + (f" (its properties: {', '.join(n for n in known if n[0] != '_')})" if known else "")
        )

    def _newProperties(self) -> PropertyMap:
        """An empty property map whose declared names are attributes of this object."""
        props = PropertyMap()
        props._owner_type = type(self)
        return props


class _PropertyAttribute:
    """The attribute of a property name on a :class:`TypedPropertyAccess` class. Instances
    that declare the property read and write it. On mtc's own classes the others have no such
    attribute (another instance's ``setProperty`` does not open the name to typos on all);
    instances of a user's subclass keep a plain attribute of that name."""

    __slots__ = ("_name",)

    def __init__(self, name: str):
        self._name = name

    def __get__(self, obj, objtype=None):
        if obj is None:
            return self
        name = self._name
        d = obj.__dict__
        props = d.get("_properties")
        if props is not None and name in props._props:
            value = props.get(name)
            getter = obj._attribute_getters.get(name)
            return _owned(getter(value) if getter else value)
        try:
            return d[name]
        except KeyError:
            raise AttributeError(f"'{type(obj).__name__}' object has no attribute '{name}'") from None

    def __set__(self, obj, value) -> None:
        name = self._name
        props = obj.__dict__.get("_properties")
        p = props._props.get(name) if props is not None else None
        if p is None:
            if type(obj).__setattr__ is TypedPropertyAccess.__setattr__:
                raise obj._no_attribute(name)
            obj.__dict__[name] = value
            return
        if value is None and p._type is not None:
            raise TypeError(f"property '{name}' expects {_type_name(p._type)}, got None")
        _not_none(value, f"property '{name}'")
        try:
            p._setValue(value)
        except PropertyError as e:
            e.setName(name)
            raise

    def __delete__(self, obj) -> None:
        try:
            del obj.__dict__[self._name]
        except KeyError:
            raise AttributeError(self._name) from None


def _install_attribute(cls: type, name: str) -> None:
    """Make the property ``name`` an attribute of ``cls``, unless the name is private or
    ``cls`` (or a base) already defines it (as a property attribute or otherwise)."""
    if not name or name[0] == "_":
        return
    for klass in cls.__mro__:
        if name in klass.__dict__:
            return
    setattr(cls, name, _PropertyAttribute(name))


# MTC's C++ names of the property errors (Property::error, Property::undeclared, ...)
Property.error = PropertyError
Property.undeclared = UndeclaredPropertyError
Property.undefined = UndefinedPropertyError
Property.type_error = PropertyTypeError
