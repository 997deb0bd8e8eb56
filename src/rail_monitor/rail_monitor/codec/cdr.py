"""CDR bytes of a message given as plain fields (:mod:`rail_monitor.messages.fields`), and the fields
of CDR bytes, without rclpy.

The encoder of a type is compiled once from its layout (codec.cdr_layout: the CDR rules, runs of
fixed-size fields): nested messages inline, and each run of consecutive fixed-size fields packed
by one ``struct`` format chosen by the run's start offset modulo 8, so a message costs a few
struct calls instead of building a message object; the test suite checks the bytes against
rosbags' serialiser and rclpy for every graph topic. Missing fields take their zero value;
unknown fields raise KeyError. The decoder is compiled the same way and reads numeric sequences
as numpy views of the bytes (no copy); bytes that do not hold one whole message raise CdrError,
a ValueError.
"""

from __future__ import annotations

import functools
import struct
from collections.abc import Callable, Mapping
from types import SimpleNamespace
from typing import Any

import numpy as np
from rosbags.interfaces import Nodetype

from rail_monitor.codec.cdr_layout import ENCAPSULATION, Run, base_dtype, layout
from rail_monitor.codec.typestore import typestore

_COUNT = struct.Struct("<I")

Encoder = Callable[[bytearray, Mapping[str, Any]], None]


def _pad(buf: bytearray, size: int) -> None:
    over = (len(buf) - 4) % size
    if over:
        buf += bytes(size - over)


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
        dtype = base_dtype(detail[0])
        size = dtype.itemsize

        def numeric(buf: bytearray, fields: Mapping[str, Any]) -> None:
            data = np.asarray(fields.get(name, () if length is None else np.zeros(length)), dtype=dtype)
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


def _steps(typename: str, run: Callable[[Run], Any], string: Callable[[str], Any], nested: Callable[[str, str], Any],
           array: Callable[[str, Any, int | None], Any]) -> list[Any]:
    """One step per item of the type's layout, made by the function for its kind (a run of
    fixed-size fields, a string, a sub-message, an array or sequence of length or None)."""
    out = []
    for item in layout(typename):
        if isinstance(item, Run):
            out.append(run(item))
            continue
        name, kind, detail = item
        out.append(string(name) if kind == Nodetype.BASE else nested(name, detail) if kind == Nodetype.NAME
                   else array(name, detail[0], detail[1] if kind == Nodetype.ARRAY else None))
    return out


@functools.cache
def _encoder(typename: str) -> Encoder:
    """The compiled encoder of a type: appends one message's CDR (no header) to a buffer."""
    known = frozenset(name for name, _ in typestore().fielddefs[typename][1])
    steps = _steps(typename, lambda run: run.encode, lambda name: functools.partial(_string_field, name),
                   lambda name, sub: _nested(name, _encoder(sub)), _array_encoder)

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


# -- reading --------------------------------------------------------------------------------------
Decoder = Callable[[memoryview, int, dict[str, Any]], int]


class CdrError(ValueError):
    """Bytes that are not a whole CDR message of the type."""


def _align(pos: int, size: int) -> int:
    return pos + (-(pos - 4) % size)


def _read_count(data: memoryview, pos: int, length: int | None = None) -> tuple[int, int]:
    """A fixed array's length, or a sequence's (or string's) uint32 count read at pos; and the
    offset after it."""
    if length is not None:
        return length, pos
    pos = _align(pos, 4)
    return _COUNT.unpack_from(data, pos)[0], pos + 4


def _read_string(data: memoryview, pos: int) -> tuple[str, int]:
    n, pos = _read_count(data, pos)
    if n < 1 or pos + n > len(data) or data[pos + n - 1] != 0:
        raise CdrError(f"a string of {n} bytes at offset {pos} does not fit or is not terminated")
    return bytes(data[pos:pos + n - 1]).decode(), pos + n


def _fields_of(container: Any) -> dict[str, Any]:
    """Where a decoder writes a sub-message's fields: the dict itself, or a namespace's __dict__."""
    return container if isinstance(container, dict) else container.__dict__


def _array_decoder(name: str, item: tuple[Any, Any], length: int | None, make: type) -> Decoder:
    kind, detail = item
    if kind == Nodetype.BASE and detail[0] != "string":
        dtype = base_dtype(detail[0])

        def numeric(data: memoryview, pos: int, out: dict[str, Any]) -> int:
            n, pos = _read_count(data, pos, length)
            if n:
                pos = _align(pos, dtype.itemsize)
            end = pos + n * dtype.itemsize
            if end > len(data):
                raise CdrError(f"field {name}: {n} values at offset {pos} run past the {len(data)} bytes")
            out[name] = np.frombuffer(data, dtype, n, pos)
            return end
        return numeric
    sub = None if kind == Nodetype.BASE else _decoder(detail, make)

    def items(data: memoryview, pos: int, out: dict[str, Any]) -> int:
        n, pos = _read_count(data, pos, length)
        if n > len(data) - pos:  # every element takes at least a byte
            raise CdrError(f"field {name}: {n} elements cannot fit in {len(data)} bytes")
        values = []
        for _ in range(n):
            if sub is None:
                value, pos = _read_string(data, pos)
            else:
                value = make()
                pos = sub(data, pos, _fields_of(value))
            values.append(value)
        out[name] = values
        return pos
    return items


@functools.cache
def _decoder(typename: str, make: type = dict) -> Decoder:
    """The compiled decoder of a type: reads one message's fields from an offset into a dict,
    returns the next; sub-messages are make() (dict, or SimpleNamespace: attributes)."""
    steps = _steps(typename, lambda run: run.decode, lambda name: functools.partial(_string_step, name),
                   lambda name, sub: functools.partial(_nested_step, name, _decoder(sub, make), make),
                   lambda name, item, length: _array_decoder(name, item, length, make))

    def decode(data: memoryview, pos: int, out: dict[str, Any]) -> int:
        for step in steps:
            pos = step(data, pos, out)
        return pos
    return decode


def _string_step(name: str, data: memoryview, pos: int, out: dict[str, Any]) -> int:
    out[name], pos = _read_string(data, pos)
    return pos


def _nested_step(name: str, sub: Decoder, make: type, data: memoryview, pos: int, out: dict[str, Any]) -> int:
    out[name] = value = make()
    return sub(data, pos, _fields_of(value))


def deserialize(typename: str, data: bytes, make: type = dict) -> Any:
    """The fields of a message of the type from its CDR bytes as make() (a dict, or with
    SimpleNamespace attributes; sub-messages alike), numeric sequences as read-only numpy arrays
    over the bytes, strings as str; CdrError for bytes too short for the message they begin
    (bytes after it are ignored, as rclpy ignores them)."""
    view = memoryview(data)
    if len(view) < 4 or bytes(view[:2]) != ENCAPSULATION[:2]:
        raise CdrError(f"not little-endian CDR (header {bytes(view[:4])!r})")
    out = make()
    try:
        _decoder(typename, make)(view, 4, _fields_of(out))
    except (struct.error, UnicodeDecodeError) as exc:
        raise CdrError(f"{typename}: {exc}") from None
    return out


def message_view(typename: str, data: bytes) -> SimpleNamespace:
    """A message of the type read from CDR bytes with its fields as attributes (sub-messages too):
    what a node reads of a message, without rclpy's conversion to Python objects; CdrError as
    :func:`deserialize`."""
    return deserialize(typename, data, SimpleNamespace)
