"""CDR bytes of a message given as plain fields (:mod:`rail_monitor.bagio.messages`), without rclpy.

The encoder of a type is compiled once from its definition in the typestore: the fields are
flattened (nested messages inline), and each run of consecutive fixed-size fields is packed by
one ``struct`` format chosen by the run's start offset modulo 8, so a message costs a few struct
calls instead of building a message object. The bytes are classic little-endian CDR as rclpy
and rosbags write it: a 4-byte encapsulation header (CDR_LE), every primitive aligned to its
size relative to the end of that header, zero padding, strings as uint32 length (with the
terminating NUL) then UTF-8 bytes and NUL, sequences as a uint32 count then the elements; the
test suite checks the bytes against rosbags' serialiser and rclpy for every graph topic.
Missing fields take their zero value; unknown fields raise KeyError.
"""

from __future__ import annotations

import functools
import struct
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np
from rosbags.interfaces import Nodetype

from rail_monitor.bagio.typestore import typestore

ENCAPSULATION = b"\x00\x01\x00\x00"  # CDR, little-endian, no options
_BASE = {"bool": "?", "int8": "b", "uint8": "B", "byte": "B", "char": "B", "int16": "h", "uint16": "H",
         "int32": "i", "uint32": "I", "int64": "q", "uint64": "Q", "float32": "f", "float64": "d"}
_COUNT = struct.Struct("<I")

Encoder = Callable[[bytearray, Mapping[str, Any]], None]


def _pad(buf: bytearray, size: int) -> None:
    over = (len(buf) - 4) % size
    if over:
        buf += bytes(size - over)


def _zero_of(name: str) -> Any:
    return False if name == "bool" else 0.0 if name.startswith("float") else 0


class _Run:
    """Consecutive fixed-size scalar fields: one struct per start offset modulo 8."""

    def __init__(self) -> None:
        self.names: list[str] = []
        self.codes: list[str] = []
        self.zeros: list[Any] = []
        self._structs: dict[int, struct.Struct] = {}

    def _struct(self, offset: int) -> struct.Struct:
        s = self._structs.get(offset)
        if s is None:
            fmt, at = "<", offset
            for code in self.codes:
                size = struct.calcsize(code)
                pad = -at % size
                fmt += "x" * pad + code
                at += pad + size
            s = self._structs[offset] = struct.Struct(fmt)
        return s

    def encode(self, buf: bytearray, fields: Mapping[str, Any]) -> None:
        s = self._struct((len(buf) - 4) % 8)
        buf += s.pack(*[fields.get(n, z) for n, z in zip(self.names, self.zeros, strict=True)])


def _string(buf: bytearray, value: str) -> None:
    data = value.encode()
    _pad(buf, 4)
    buf += _COUNT.pack(len(data) + 1)
    buf += data
    buf += b"\x00"


def _string_field(name: str, buf: bytearray, fields: Mapping[str, Any]) -> None:
    _string(buf, fields.get(name, ""))


def _array_encoder(name: str, item: tuple[Any, Any], length: int | None) -> Encoder:
    """A fixed array (length) or a sequence (None) of base types, strings or messages."""
    kind, detail = item
    if kind == Nodetype.BASE and detail[0] != "string":
        dtype = np.dtype(_BASE[detail[0]]).newbyteorder("<")
        size = dtype.itemsize

        def numeric(buf: bytearray, fields: Mapping[str, Any]) -> None:
            data = np.asarray(fields.get(name, ()), dtype=dtype)
            if data.ndim != 1 or (length is not None and len(data) != length):
                raise ValueError(f"field {name}: expected {length or 'a sequence of'} values, got shape {data.shape}")
            if length is None:
                _pad(buf, 4)
                buf += _COUNT.pack(len(data))
            if len(data):
                _pad(buf, size)
                buf += data.tobytes()
        return numeric
    each: Callable[[bytearray, Any], None] = _string if kind == Nodetype.BASE else _encoder(detail)

    def items(buf: bytearray, fields: Mapping[str, Any]) -> None:
        values = fields.get(name)
        if values is None:
            values = [("" if kind == Nodetype.BASE else {})] * (length or 0)
        if length is not None and len(values) != length:
            raise ValueError(f"field {name}: expected {length} values, got {len(values)}")
        if length is None:
            _pad(buf, 4)
            buf += _COUNT.pack(len(values))
        for v in values:
            each(buf, v)
    return items


def _nested(name: str, sub: Encoder) -> Encoder:
    return lambda buf, f: sub(buf, f.get(name, {}))


@functools.cache
def _encoder(typename: str) -> Encoder:
    """The compiled encoder of a type: appends one message's CDR (no header) to a buffer."""
    defs = typestore().fielddefs[typename][1]
    known = frozenset(name for name, _ in defs)
    steps: list[Encoder] = []
    run: _Run | None = None
    for name, (kind, detail) in defs:
        if kind == Nodetype.BASE and detail[0] != "string":
            if run is None:
                run = _Run()
                steps.append(run.encode)
            run.names.append(name)
            run.codes.append(_BASE[detail[0]])
            run.zeros.append(_zero_of(detail[0]))
            continue
        run = None
        if kind == Nodetype.BASE:
            steps.append(functools.partial(_string_field, name))
        elif kind == Nodetype.NAME:
            steps.append(_nested(name, _encoder(detail)))
        else:
            steps.append(_array_encoder(name, detail[0], detail[1] if kind == Nodetype.ARRAY else None))

    def encode(buf: bytearray, fields: Mapping[str, Any]) -> None:
        if not fields.keys() <= known:
            raise KeyError(f"{typename} has no field(s) {sorted(set(fields) - known)}")
        for step in steps:
            step(buf, fields)
    return encode


def serialize(typename: str, fields: Mapping[str, Any]) -> bytes:
    """CDR bytes of a message of the type with these fields."""
    buf = bytearray(ENCAPSULATION)
    _encoder(typename)(buf, fields)
    return bytes(buf)
