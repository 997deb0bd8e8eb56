"""Many messages of one type written at once from columns: the CDR bytes of each, as
codec.cdr.serialize writes them one by one (the tests hold the two to the same bytes).

The columns are those codec.cdr_columns.read_columns gives (numbers (n,), fixed arrays and
sequences (n, length) or one array per message, strings a list of str, sequences of strings a
list of lists, sub-messages a namespace or dict of their own columns). Every message's field
offsets follow from its strings' and sequences' lengths and CDR's alignment, computed for all
messages at once; each field is then written into one zeroed buffer for every message in one
numpy step (strings, and sequences whose lengths differ, joined and scattered in one step too).
A few messages are written one by one.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import SimpleNamespace
from typing import Any

import numpy as np
from rosbags.interfaces import Nodetype

from rail_monitor.codec.cdr import serialize
from rail_monitor.codec.cdr_columns import FEW
from rail_monitor.codec.cdr_layout import ENCAPSULATION, Run, base_dtype, layout, run_dtype


def _get(values: Any, name: str) -> Any:
    try:
        return values[name] if isinstance(values, Mapping) else getattr(values, name)
    except (KeyError, AttributeError):
        raise KeyError(f"no column {name}") from None


class _Plan:
    """Per message: the offset of the next field (from the message's start), and the writes."""

    def __init__(self, n: int) -> None:
        self.pos = np.full(n, len(ENCAPSULATION), np.int64)
        self.blocks: list[tuple[Any, np.ndarray, np.ndarray]] = []   # rows, offsets, (rows, width) bytes
        # strings, and arrays whose lengths differ between messages: per message the offset and the
        # length of its piece, and the pieces joined
        self.pieces: list[tuple[np.ndarray, np.ndarray, bytes]] = []

    def align(self, size: int, where: np.ndarray | None = None) -> None:
        step = -(self.pos - 4) % size
        self.pos += step if where is None else np.where(where, step, 0)

    def put(self, rows: Any, data: np.ndarray) -> None:
        """Bytes (rows, width) at the offsets of rows; the offsets move on."""
        self.blocks.append((rows, self.pos[rows].copy(), data))
        self.pos[rows] += data.shape[1]

    def count(self, n: np.ndarray, active: np.ndarray | None = None) -> None:
        rows = slice(None) if active is None else np.flatnonzero(active)
        self.align(4, active)
        self.put(rows, np.ascontiguousarray(np.asarray(n, "<u4")[rows]).view(np.uint8).reshape(-1, 4))

    def string(self, texts: list[str | None], active: np.ndarray | None = None) -> None:
        data = [b"" if t is None else t.encode() for t in texts]
        present = np.fromiter((t is not None for t in texts), bool, len(texts))
        lengths = np.fromiter(map(len, data), np.int64, len(data))
        size = np.where(present, lengths + 1, 0)   # the NUL included (the buffer is zeroed)
        self.count(size, present if active is None else active)
        self.pieces.append((self.pos.copy(), lengths, b"".join(data)))
        self.pos += size


def _plan(plan: _Plan, typename: str, values: Any, n: int) -> None:
    for item in layout(typename):
        if isinstance(item, Run):
            phase = (plan.pos - 4) % 8
            for p in np.unique(phase).tolist():
                rows = np.flatnonzero(phase == p)
                rec = np.zeros(len(rows), run_dtype(item, p))
                for name in item.names:
                    rec[name] = _fitting(name, np.asarray(_get(values, name))[rows], rec.dtype[name])
                plan.put(rows, rec.view(np.uint8).reshape(len(rows), -1))
            continue
        name, kind, detail = item
        value = _get(values, name)
        if kind == Nodetype.BASE:
            plan.string(list(value))
        elif kind == Nodetype.NAME:
            _plan(plan, detail, value, n)
        else:
            (item_kind, item_detail), length = detail[0], detail[1] if kind == Nodetype.ARRAY else None
            if item_kind != Nodetype.BASE:
                raise TypeError(f"{typename}.{name}: sequences of messages are not written from columns")
            if item_detail[0] == "string":
                _strings(plan, value, length)
            else:
                _numbers(plan, name, value, base_dtype(item_detail[0]), length, n)


def _fitting(name: str, value: np.ndarray, dtype: np.dtype) -> np.ndarray:
    """value, unless an integer field cannot hold one of its values (numpy would wrap it; struct,
    writing one message, refuses it)."""
    if dtype.kind in "iu" and value.size:
        info = np.iinfo(dtype)
        if value.min() < info.min or value.max() > info.max:
            raise ValueError(f"field {name}: a value is outside {info.min}-{info.max}")
    return value


def _numbers(plan: _Plan, name: str, value: Any, dtype: np.dtype, length: int | None, n: int) -> None:
    rows = [np.asarray(v, dtype) for v in value] if isinstance(value, list) else None
    counts = (np.fromiter(map(len, rows), np.int64, n) if rows is not None
              else np.full(n, np.shape(value)[1] if np.ndim(value) == 2 else 0, np.int64))
    if length is not None and np.any(counts != length):
        raise ValueError(f"field {name}: expected {length} values per message")
    if length is None:
        plan.count(counts)
    plan.align(dtype.itemsize, counts > 0)
    if rows is None:
        block = np.ascontiguousarray(np.asarray(value, dtype)).reshape(n, -1)
        plan.put(slice(None), block.view(np.uint8).reshape(n, -1))
    else:
        size = counts * dtype.itemsize
        plan.pieces.append((plan.pos.copy(), size, np.concatenate(rows).tobytes() if rows else b""))
        plan.pos += size


def _strings(plan: _Plan, value: list[list[str]], length: int | None) -> None:
    counts = np.fromiter(map(len, value), np.int64, len(value))
    if length is None:
        plan.count(counts)
    for j in range(int(counts.max(initial=0))):
        plan.string([v[j] if j < len(v) else None for v in value], counts > j)


def _row(values: Any, i: int) -> Any:
    """Message i of the columns as plain fields (codec.cdr.serialize's input)."""
    items = values.items() if isinstance(values, Mapping) else vars(values).items()
    return {k: _row(v, i) if isinstance(v, (Mapping, SimpleNamespace)) else v[i] for k, v in items}


def serialize_columns(typename: str, values: Any, n: int) -> list[bytes]:
    """The CDR bytes of each of the n messages of the type in columns."""
    if n < FEW:
        return [serialize(typename, _row(values, i)) for i in range(n)]
    plan = _Plan(n)
    _plan(plan, typename, values, n)
    start = np.zeros(n + 1, np.int64)
    np.cumsum(plan.pos, out=start[1:])
    raw = bytearray(int(start[-1]))
    buf = np.frombuffer(raw, np.uint8)
    buf[start[:-1] + 1] = ENCAPSULATION[1]
    for rows, offsets, data in plan.blocks:
        if data.size:
            buf[(start[:-1][rows] + offsets)[:, None] + np.arange(data.shape[1])] = data
    for offsets, lengths, joined in plan.pieces:
        if joined:  # byte j of the joined pieces, in piece k, goes to k's offset + (j - k's start)
            shift = start[:-1] + offsets - (np.cumsum(lengths) - lengths)
            buf[np.repeat(shift, lengths) + np.arange(len(joined))] = np.frombuffer(joined, np.uint8)
    whole = bytes(raw)
    return [whole[a:b] for a, b in zip(start[:-1].tolist(), start[1:].tolist(), strict=True)]
