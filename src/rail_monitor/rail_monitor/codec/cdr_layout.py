"""The layout of a ROS 2 message type in CDR, shared by the readers and writers of bagio: one
message at a time (codec.cdr) and many as columns (codec.cdr_columns, codec.cdr_from_columns).

Classic little-endian CDR as rclpy and rosbags write it: a 4-byte encapsulation header (CDR_LE),
every primitive aligned to its size relative to the end of that header, zero padding, strings as
uint32 length (with the terminating NUL) then UTF-8 bytes and NUL, sequences as a uint32 count
then the elements. A type's fields come from its definition in the typestore; consecutive
fixed-size scalars form a Run, packed by one ``struct`` format per start offset modulo 8.
"""

from __future__ import annotations

import functools
import struct
from collections.abc import Mapping
from typing import Any

import numpy as np
from rosbags.interfaces import Nodetype

from rail_monitor.codec.typestore import typestore

ENCAPSULATION = b"\x00\x01\x00\x00"  # CDR, little-endian, no options
BASE_CODES = {"bool": "?", "int8": "b", "uint8": "B", "byte": "B", "char": "B", "int16": "h", "uint16": "H",
              "int32": "i", "uint32": "I", "int64": "q", "uint64": "Q", "float32": "f", "float64": "d"}


def base_dtype(name: str) -> np.dtype:
    """The little-endian numpy type of a numeric base type (e.g. float64)."""
    return np.dtype(BASE_CODES[name]).newbyteorder("<")


def _zero_of(name: str) -> Any:
    return False if name == "bool" else 0.0 if name.startswith("float") else 0


class Run:
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

    def decode(self, data: memoryview, pos: int, out: dict[str, Any]) -> int:
        s = self._struct((pos - 4) % 8)
        out.update(zip(self.names, s.unpack_from(data, pos), strict=True))
        return pos + s.size


@functools.cache
def layout(typename: str) -> tuple[Run | tuple[str, int, Any], ...]:
    """A type's fields in order: consecutive fixed-size ones as one Run, the others as
    (name, node kind, node detail); shared by its encoder and its decoder."""
    out: list[Run | tuple[str, int, Any]] = []
    for name, (kind, detail) in typestore().fielddefs[typename][1]:
        if kind == Nodetype.BASE and detail[0] != "string":
            if not out or not isinstance(out[-1], Run):
                out.append(Run())
            run = out[-1]
            run.names.append(name)
            run.codes.append(BASE_CODES[detail[0]])
            run.zeros.append(_zero_of(detail[0]))
        else:
            out.append((name, kind, detail))
    return tuple(out)


@functools.cache
def run_dtype(run: Run, phase: int) -> np.dtype:
    """The numpy record of a run of fixed-size scalars starting phase bytes past an 8-byte boundary
    (CDR alignment, counted from the end of the encapsulation header); bools as bytes."""
    names, formats, offsets, at = [], [], [], phase
    for name, code in zip(run.names, run.codes, strict=True):
        dtype = np.dtype("u1" if code == "?" else code).newbyteorder("<")
        at += -at % dtype.itemsize
        names.append(name)
        formats.append(dtype)
        offsets.append(at - phase)
        at += dtype.itemsize
    return np.dtype({"names": names, "formats": formats, "offsets": offsets, "itemsize": at - phase})


@functools.cache
def column_dtype(run: Run) -> np.dtype:
    """A packed record of a run's fields as their columns are typed (bools as bool, little-endian)."""
    return np.dtype([(name, bool if code == "?" else np.dtype(code).newbyteorder("<"))
                     for name, code in zip(run.names, run.codes, strict=True)])
