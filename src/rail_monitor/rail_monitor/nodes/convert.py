"""rclpy messages, and the CDR bytes the nodes publish, of the plain fields of
:mod:`rail_monitor.messages.fields` (the one place each message's fields are written), and the
graph's topic table with rclpy types and profiles."""

from __future__ import annotations

import functools
import importlib
from collections.abc import Mapping
from typing import Any

from builtin_interfaces.msg import Time

from rail_monitor.codec.cdr import serialize
from rail_monitor.codec.cdr_from_columns import serialize_columns
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.messages import fields as messages
from rail_monitor.messages.topics import GRAPH_TOPICS, OPTIONAL_TOPICS
from rail_monitor.nodes.qos import profile

_SCALARS = {"boolean": bool, "float": float, "double": float, "string": str}


def message_class(typename: str) -> type:
    """The generated rclpy class of 'pkg/msg/Type'; RailMonitorError when it is not installed."""
    pkg, kind, name = typename.split("/")
    try:
        return getattr(importlib.import_module(f"{pkg}.{kind}"), name)
    except (ImportError, AttributeError):
        raise RailMonitorError(f"message type {typename} is not installed") from None


# The recorded topics with their rclpy message class and publisher profile.
TOPICS: dict[str, tuple[type, Any]] = {name: (message_class(t), profile(q)) for name, (t, q) in GRAPH_TOPICS.items()}


def output_publishers(node: Any, topics: tuple[str, ...]) -> dict[str, Any]:
    """Publishers of graph topics (relative names), by topic, with the graph's QoS."""
    pubs = {}
    for topic in topics:
        typename, qos = GRAPH_TOPICS.get(topic) or OPTIONAL_TOPICS[topic]
        pubs[topic] = node.create_publisher(message_class(typename), topic, profile(qos))
    return pubs


@functools.cache
def _slots(cls: type) -> dict[str, tuple[str, Any]]:
    """Per field of a message class: ('msg', class), ('msgs', class), or ('value', cast)."""
    out: dict[str, tuple[str, Any]] = {}
    for name, kind in cls.get_fields_and_field_types().items():
        inner = kind[len("sequence<"):-1] if kind.startswith("sequence<") else kind
        if "/" in inner:
            pkg, msg = inner.split("/")
            sub = message_class(f"{pkg}/msg/{msg}")
            out[name] = ("msgs" if inner != kind else "msg", sub)
        else:
            out[name] = ("value", _SCALARS.get(kind, int) if inner == kind and "[" not in kind else None)
    return out


def to_msg(cls: type, fields: Mapping[str, Any]) -> Any:
    """An rclpy message of a class from plain fields (sub-messages as dicts, arrays as lists);
    scalars are cast to the field's Python type (rclpy refuses numpy scalars)."""
    slots = _slots(cls)
    kwargs = {}
    for name, value in fields.items():
        kind, how = slots[name]
        if kind == "msg":
            kwargs[name] = to_msg(how, value)
        elif kind == "msgs":
            kwargs[name] = [to_msg(how, v) for v in value]
        else:
            kwargs[name] = how(value) if how is not None else value
    return cls(**kwargs)


@functools.cache
def typename_of(cls: type) -> str:
    """'pkg/msg/Type' of a generated rclpy class (message_class's inverse)."""
    return f"{cls.__module__.split('.')[0]}/msg/{cls.__name__}"


def to_cdr(cls: type, fields: Mapping[str, Any]) -> bytes:
    """The CDR bytes of to_msg(cls, fields), packed by codec.cdr's compiled encoder: what the nodes
    publish (rclpy sends bytes as they are), so no rclpy message is built and converted per output."""
    return serialize(typename_of(cls), fields)


def to_cdr_many(cls: type, columns: Any, n: int) -> list[bytes]:
    """The CDR bytes of n messages given as columns (codec.cdr_from_columns), as to_cdr gives each."""
    return serialize_columns(typename_of(cls), columns, n)


def time_msg(ns: int) -> Time:
    """builtin_interfaces/Time of ns since the epoch."""
    return to_msg(Time, messages.time_fields(ns))
