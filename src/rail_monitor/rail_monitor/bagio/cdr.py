"""CDR bytes of a message given as plain fields (:mod:`rail_monitor.bagio.messages`), without rclpy.

rosbags' serialiser writes the same CDR as rclpy's (little-endian, aligned, zero padding); the
test suite checks the bytes against rclpy's for every graph topic.
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from typing import Any

import numpy as np
from rosbags.interfaces import Nodetype

from rail_monitor.bagio.typestore import typestore

_DTYPES = {"bool": np.bool_, "int8": np.int8, "uint8": np.uint8, "byte": np.uint8, "char": np.uint8,
           "int16": np.int16, "uint16": np.uint16, "int32": np.int32, "uint32": np.uint32, "int64": np.int64,
           "uint64": np.uint64, "float32": np.float32, "float64": np.float64}


def _zero(node: tuple[Any, Any]) -> Any:
    kind, detail = node
    if kind == Nodetype.BASE:
        name = detail[0]
        return "" if name == "string" else False if name == "bool" else 0.0 if name.startswith("float") else 0
    if kind == Nodetype.NAME:
        return build(detail, {})
    if kind == Nodetype.ARRAY:
        return _sequence(detail[0], [_zero(detail[0])] * detail[1])
    return _sequence(detail[0], [])


def _sequence(item: tuple[Any, Any], values: Any) -> Any:
    kind, detail = item
    if kind == Nodetype.BASE and detail[0] != "string":
        return np.asarray(values, dtype=_DTYPES[detail[0]])
    return [_value(item, v) for v in values]


def _value(node: tuple[Any, Any], value: Any) -> Any:
    kind, detail = node
    if kind == Nodetype.NAME:
        return build(detail, value)
    if kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):
        return _sequence(detail[0], value)
    return value


@functools.cache
def _fields(typename: str) -> list[tuple[str, tuple[Any, Any]]]:
    return typestore().fielddefs[typename][1]


def build(typename: str, fields: Mapping[str, Any]) -> Any:
    """The rosbags message object of a type from its fields (missing fields: zero values)."""
    known = _fields(typename)
    unknown = set(fields) - {name for name, _ in known}
    if unknown:
        raise KeyError(f"{typename} has no field(s) {sorted(unknown)}")
    kwargs = {name: _value(node, fields[name]) if name in fields else _zero(node) for name, node in known}
    return typestore().types[typename](**kwargs)


def serialize(typename: str, fields: Mapping[str, Any]) -> bytes:
    """CDR bytes of a message of the type with these fields."""
    return bytes(typestore().serialize_cdr(build(typename, fields), typename))
