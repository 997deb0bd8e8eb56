"""Many CDR messages of one type read at once, field by field, into numpy columns.

A node that takes a backlog reads it in one step per field instead of one step per field per
message: the messages' bytes are joined, and each field is read for every message at once from
the offset where it lies in each. The offsets follow from the lengths of the strings and
sequences before the field and from CDR's alignment (codec.cdr's module docstring), all computed
as integer arrays. A message that is not one whole CDR message of the type is left out; the
per-message reader (codec.cdr.deserialize) then gives its error, so the two readers refuse the
same bytes in the same words, and the tests hold them to the same values.

Columns: numbers (n,); fixed arrays and sequences of one length (n, length); sequences whose
lengths differ, a list of 1-D arrays; strings, a list of str; sequences of strings, a list of
lists; sub-messages, a namespace of their own columns. Types holding sequences of messages are
not read this way (TypeError).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Any

import numpy as np
from rosbags.interfaces import Nodetype

from rail_monitor.codec.cdr import CdrError, deserialize, message_view
from rail_monitor.codec.cdr_layout import ENCAPSULATION, Run, base_dtype, column_dtype, layout, run_dtype


@dataclass
class Columns:
    """The messages read (``values``: their fields as columns, see the module docstring), the
    positions among the given bytes of those read (``index``), and the others with the error the
    per-message reader gives them (``refused``)."""

    values: SimpleNamespace
    index: np.ndarray
    refused: list[tuple[int, CdrError]] = field(default_factory=list)

    def __len__(self) -> int:
        return len(self.index)


class _Walk:
    """Per message: where the next field starts in the joined bytes, and whether it is whole so far
    (a message refused reads from its start, so that no read leaves the bytes)."""

    def __init__(self, raws: Sequence[bytes]) -> None:
        n = len(raws)
        length = np.fromiter(map(len, raws), np.int64, n)
        self.start = np.zeros(n, np.int64)
        np.cumsum(length[:-1], out=self.start[1:])
        self.end = self.start + length
        self.data = b"".join(raws)
        self.buf = np.frombuffer(self.data + bytes(8), np.uint8)
        self.ok = length >= 4
        self.pos = np.where(self.ok, self.start + 4, self.start)
        head = self._bytes(self.start, 2)
        self._refuse((head[:, 0] != ENCAPSULATION[0]) | (head[:, 1] != ENCAPSULATION[1]))

    def _refuse(self, bad: np.ndarray) -> None:
        if bad.any():
            self.ok &= ~bad
            self.pos = np.where(self.ok, self.pos, self.start)

    def _bytes(self, pos: np.ndarray, size: int) -> np.ndarray:
        """(n, size) bytes from pos per message."""
        return self.buf.take(pos[:, None] + np.arange(size), mode="clip")

    def _align(self, size: int, where: np.ndarray | None = None) -> None:
        step = -(self.pos - self.start - 4) % size
        self.pos += step if where is None else np.where(where, step, 0)

    def run(self, run: Run) -> dict[str, np.ndarray]:
        """The fields of a run of fixed-size scalars per message: one read per distinct start
        offset modulo 8 (the run's layout, padding included, depends on it alone)."""
        phase = (self.pos - self.start - 4) % 8
        kinds = phase[:1] if not len(phase) or (phase == phase[0]).all() else np.unique(phase)
        kinds = kinds if len(kinds) else np.zeros(1, np.int64)
        out: dict[str, np.ndarray] = {}
        for p in kinds.tolist():
            rows = slice(None) if len(kinds) == 1 else np.flatnonzero(phase == p)
            dtype = run_dtype(run, p)
            self._refuse((self.pos + dtype.itemsize > self.end) & (phase == p))
            got = self._bytes(self.pos[rows], dtype.itemsize).view(dtype)[:, 0]
            for name, code in zip(run.names, run.codes, strict=True):
                value = got[name] != 0 if code == "?" else got[name]
                if len(kinds) == 1:
                    out[name] = value.copy()
                else:
                    out.setdefault(name, np.zeros(len(phase), value.dtype))[rows] = value
            self.pos[rows] += dtype.itemsize
        return out

    def count(self, active: np.ndarray | None = None) -> np.ndarray:
        """A sequence's or string's uint32 count (0 for a message refused, or not active)."""
        self._align(4, active)
        fits = self.pos + 4 <= self.end
        self._refuse(~fits if active is None else ~fits & active)
        n = self._bytes(self.pos, 4).view("<u4")[:, 0].astype(np.int64)
        live = self.ok if active is None else self.ok & active
        self.pos += np.where(live, 4, 0)
        return np.where(live, n, 0)

    def string(self, active: np.ndarray | None = None) -> list[str | None]:
        """A string per (active) message (None where refused, or not active)."""
        active = np.ones(len(self.pos), bool) if active is None else active
        n = self.count(active)
        last = self.pos + n - 1
        fits = (n >= 1) & (last < self.end)
        self._refuse(active & ~(fits & (self._bytes(np.where(fits, last, self.start), 1)[:, 0] == 0)))
        rows = np.flatnonzero(self.ok & active)
        data, starts, ends = self.data, self.pos[rows].tolist(), (self.pos[rows] + n[rows] - 1).tolist()
        try:
            texts: list[str | None] = [data[a:b].decode() for a, b in zip(starts, ends, strict=True)]
        except UnicodeDecodeError:  # one by one: the messages whose string is not UTF-8 are refused
            texts = [_utf8(data[a:b]) for a, b in zip(starts, ends, strict=True)]
            self._refuse(np.isin(np.arange(len(n)), rows[[t is None for t in texts]]))
        if len(rows) == len(n):
            out = texts
        else:
            out = [None] * len(n)
            for i, text in zip(rows.tolist(), texts, strict=True):
                out[i] = text
        self.pos += np.where(self.ok & active, n, 0)
        return out

    def _elements(self, pos: np.ndarray, k: int, dtype: np.dtype) -> np.ndarray:
        """(n, k) values from pos per message, read as values (not bytes) from the bytes viewed at
        each offset modulo the value's size (a message already refused reads from its start)."""
        size, out = dtype.itemsize, np.empty((len(pos), k), dtype)
        residue = pos % size
        for r in (residue[:1] if (residue == residue[0]).all() else np.unique(residue)).tolist():
            rows = slice(None) if (residue == r).all() else residue == r
            values = np.frombuffer(self.buf, dtype, (len(self.buf) - r) // size, r)
            out[rows] = values.take(((pos[rows] - r) // size)[:, None] + np.arange(k), mode="clip")
        return out

    def numbers(self, code: str, length: int | None) -> Any:
        """A fixed array (length) or a sequence (None) of one numeric type per message."""
        dtype = base_dtype(code)
        n = np.full(len(self.pos), length, np.int64) if length is not None else self.count()
        self._align(dtype.itemsize, n > 0)
        stop = self.pos + n * dtype.itemsize
        self._refuse(stop > self.end)
        counts = np.unique(n[self.ok])
        if len(counts) <= 1:   # one length (or none read): a 2-D column
            k = int(counts[0]) if len(counts) else (length or 0)
            out = self._elements(self.pos, k, dtype) if k else np.zeros((len(n), 0), dtype)
        else:
            ok, at = self.ok.tolist(), self.pos.tolist()
            out = [np.frombuffer(self.data, dtype, int(n[i]), at[i]) if ok[i] else None for i in range(len(n))]
        self.pos = np.where(self.ok, stop, self.pos)
        return out


def _utf8(data: bytes) -> str | None:
    try:
        return data.decode()
    except UnicodeDecodeError:
        return None


def _read(walk: _Walk, typename: str) -> SimpleNamespace:
    out = SimpleNamespace()
    for item in layout(typename):
        if isinstance(item, Run):
            vars(out).update(walk.run(item))
            continue
        name, kind, detail = item
        if kind == Nodetype.BASE:
            value: Any = walk.string()
        elif kind == Nodetype.NAME:
            value = _read(walk, detail)
        else:
            (item_kind, item_detail), length = detail[0], detail[1] if kind == Nodetype.ARRAY else None
            if item_kind != Nodetype.BASE:
                raise TypeError(f"{typename}.{name}: sequences of messages are not read as columns")
            value = walk.numbers(item_detail[0], length) if item_detail[0] != "string" else _strings(walk, length)
        setattr(out, name, value)
    return out


def _strings(walk: _Walk, length: int | None) -> list[list[str] | None]:
    """A fixed array or sequence of strings per message, element j read for the messages that have one."""
    n = np.full(len(walk.pos), length, np.int64) if length is not None else walk.count()
    walk._refuse(n > walk.end - walk.pos)   # every string takes at least a byte
    n = np.where(walk.ok, n, 0)
    out: list[list[Any]] = [[] for _ in range(len(n))]
    for j in range(int(n.max(initial=0))):
        for i, s in enumerate(walk.string(n > j)):
            if s is not None:
                out[i].append(s)
    return [v if ok else None for v, ok in zip(out, walk.ok.tolist(), strict=True)]


def _rows(value: Any, keep: np.ndarray) -> Any:
    """The columns of the messages at keep."""
    if isinstance(value, SimpleNamespace):
        return SimpleNamespace(**{k: _rows(v, keep) for k, v in vars(value).items()})
    if isinstance(value, np.ndarray):
        return value[keep]
    return [value[i] for i in keep.tolist()]


FEW = 12  # fewer messages than this are read one by one (a numpy step per field costs more than a message)


def _stack(typename: str, views: list[SimpleNamespace]) -> SimpleNamespace:
    """The columns of messages read one by one (codec.cdr.message_view), as read_columns gives them."""
    out = SimpleNamespace()
    for item in layout(typename):
        if isinstance(item, Run):  # one record array per run, its fields the columns
            rec = np.array([tuple(getattr(v, name) for name in item.names) for v in views], column_dtype(item))
            vars(out).update({name: rec[name] for name in item.names})
            continue
        name, kind, detail = item
        values = [getattr(v, name) for v in views]
        if kind == Nodetype.NAME:
            values = _stack(detail, values)
        elif kind != Nodetype.BASE and detail[0][1][0] != "string":
            lengths = {len(v) for v in values}
            if len(lengths) <= 1:
                dtype = base_dtype(detail[0][1][0])
                values = np.array(values, dtype) if values and lengths != {0} else np.zeros((len(values), 0), dtype)
        setattr(out, name, values)
    return out


def read_columns(typename: str, raws: Sequence[bytes]) -> Columns:
    """The messages of the type in raws (CDR bytes each) as columns, in order, and those that are
    not whole messages of the type, each with the per-message reader's CdrError."""
    if len(raws) < FEW:
        views, index, refused = [], [], []
        for i, raw in enumerate(raws):
            try:
                views.append(message_view(typename, raw))
                index.append(i)
            except CdrError as exc:
                refused.append((i, exc))
        return Columns(_stack(typename, views), np.array(index, np.intp), refused)
    walk = _Walk(raws)
    values = _read(walk, typename)
    keep = np.flatnonzero(walk.ok)
    refused = []
    for i in np.flatnonzero(~walk.ok).tolist():
        try:
            deserialize(typename, raws[i])
        except CdrError as exc:
            refused.append((i, exc))
            continue
        raise AssertionError(f"{typename}: message {i} read whole by codec.cdr but not as columns")
    return Columns(values if len(keep) == len(raws) else _rows(values, keep), keep, refused)
