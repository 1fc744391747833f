"""Parse MoveIt's Semantic Robot Description Format (SRDF).

The SRDF names what the URDF leaves implicit: planning groups, named group states, end
effectors, virtual and passive joints, and link pairs whose collisions are never checked.
This module only reads the XML into plain dataclasses; :mod:`mtc.scene.robot_model` resolves
the names against the URDF.
"""

from __future__ import annotations

import logging
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

log = logging.getLogger(__name__)


class DescriptionError(ValueError):
    """A URDF, SRDF or mesh file could not be read or is inconsistent."""


@dataclass
class GroupSpec:
    """A ``<group>`` element, unresolved: the names as written."""

    name: str
    joints: list[str] = field(default_factory=list)
    links: list[str] = field(default_factory=list)
    chains: list[tuple[str, str]] = field(default_factory=list)
    subgroups: list[str] = field(default_factory=list)


@dataclass
class GroupStateSpec:
    """A ``<group_state>``: named joint values of one group."""

    name: str
    group: str
    values: dict[str, float] = field(default_factory=dict)


@dataclass
class EndEffectorSpec:
    """An ``<end_effector>``: a group attached to a parent link of a parent group."""

    name: str
    group: str
    parent_link: str
    parent_group: str = ""


@dataclass
class VirtualJointSpec:
    """A ``<virtual_joint>`` connecting the robot's root link to a fixed frame."""

    name: str
    type: str
    parent_frame: str
    child_link: str


@dataclass
class SRDF:
    """Everything an SRDF declares, in file order."""

    name: str = ""
    label: str = field(default="SRDF", compare=False)  # the source in errors: "SRDF file '<path>'", "SRDF text"
    groups: list[GroupSpec] = field(default_factory=list)
    group_states: list[GroupStateSpec] = field(default_factory=list)
    end_effectors: list[EndEffectorSpec] = field(default_factory=list)
    virtual_joints: list[VirtualJointSpec] = field(default_factory=list)
    passive_joints: list[str] = field(default_factory=list)
    disabled_collisions: list[tuple[str, str, str]] = field(default_factory=list)


def read_xml_source(source: str, what: str) -> tuple[str, str]:
    """Return ``(xml_text, label)`` for a file path or XML text.

    Args:
        source: a path to a file, or the XML document itself.
        what: "URDF" or "SRDF", for error messages.

    Raises:
        DescriptionError: the file does not exist or cannot be read.
    """
    if not isinstance(source, (str, os.PathLike)):
        raise DescriptionError(f"{what} must be a file path or XML text, got {type(source).__name__}")
    text = os.fspath(source)
    if text.lstrip().startswith("<"):
        return text, f"{what} text"
    if not os.path.isfile(text):
        raise DescriptionError(f"{what} file not found: '{text}'")
    try:
        with open(text, encoding="utf-8") as f:
            return f.read(), f"{what} file '{text}'"
    except OSError as e:
        raise DescriptionError(f"cannot read {what} file '{text}': {e}") from e


def parse_xml(text: str, label: str, root_tag: str = "robot") -> ET.Element:
    """Parse XML text and check its root element, naming ``label`` in errors."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as e:
        raise DescriptionError(f"malformed XML in {label}: {e}") from e
    if root.tag != root_tag:
        raise DescriptionError(f"{label}: root element is <{root.tag}>, expected <{root_tag}>")
    return root


def _attr(elem: ET.Element, name: str, label: str) -> str:
    value = elem.get(name)
    if value is None or value == "":
        raise DescriptionError(f"{label}: <{elem.tag}> lacks the attribute '{name}'")
    return value


def parse_srdf(source: str) -> SRDF:
    """Read an SRDF from a path or XML text.

    Raises:
        DescriptionError: the file is missing, malformed, or an element lacks a required attribute.
    """
    text, label = read_xml_source(source, "SRDF")
    root = parse_xml(text, label)
    srdf = SRDF(name=root.get("name", ""), label=label)
    for elem in root:
        tag = elem.tag
        if tag == "group":
            group = GroupSpec(_attr(elem, "name", label))
            for sub in elem:
                if sub.tag == "joint":
                    group.joints.append(_attr(sub, "name", label))
                elif sub.tag == "link":
                    group.links.append(_attr(sub, "name", label))
                elif sub.tag == "chain":
                    group.chains.append((_attr(sub, "base_link", label), _attr(sub, "tip_link", label)))
                elif sub.tag == "group":
                    group.subgroups.append(_attr(sub, "name", label))
            if any(g.name == group.name for g in srdf.groups):
                raise DescriptionError(f"{label}: group '{group.name}' is defined twice")
            srdf.groups.append(group)
        elif tag == "group_state":
            if not elem.get("group"):
                # Pinocchio's reference configurations (example-robot-data's SRDFs) name no
                # group; MoveIt's SRDF reader skips them too
                log.warning("%s: group_state '%s' names no group; ignored", label, elem.get("name", ""))
                continue
            state = GroupStateSpec(_attr(elem, "name", label), _attr(elem, "group", label))
            for sub in elem:
                if sub.tag == "joint":
                    raw = _attr(sub, "value", label)
                    try:
                        # multi-variable joints list several values; mtc joints have one
                        state.values[_attr(sub, "name", label)] = float(raw.split()[0])
                    except ValueError as e:
                        raise DescriptionError(
                            f"{label}: group_state '{state.name}' has a non-numeric value '{raw}'"
                        ) from e
            srdf.group_states.append(state)
        elif tag == "end_effector":
            srdf.end_effectors.append(
                EndEffectorSpec(
                    _attr(elem, "name", label),
                    _attr(elem, "group", label),
                    _attr(elem, "parent_link", label),
                    elem.get("parent_group", ""),
                )
            )
        elif tag == "virtual_joint":
            srdf.virtual_joints.append(
                VirtualJointSpec(
                    _attr(elem, "name", label),
                    _attr(elem, "type", label),
                    _attr(elem, "parent_frame", label),
                    _attr(elem, "child_link", label),
                )
            )
        elif tag == "passive_joint":
            srdf.passive_joints.append(_attr(elem, "name", label))
        elif tag in ("disable_collisions", "disable_default_collisions"):
            if tag == "disable_default_collisions":
                link = _attr(elem, "link", label)
                srdf.disabled_collisions.append((link, "*", elem.get("reason", "")))
            else:
                srdf.disabled_collisions.append(
                    (_attr(elem, "link1", label), _attr(elem, "link2", label), elem.get("reason", ""))
                )
    return srdf
