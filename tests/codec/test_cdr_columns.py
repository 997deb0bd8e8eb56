"""Messages read together as columns (rail_monitor.codec.cdr_columns) against the per-message
reader (rail_monitor.codec.cdr.message_view), both ways the columns are read (a few messages one
by one and stacked, more field by field): the same values bit for bit, row by row, and the same
bytes refused with the same error, on random messages of every graph type that has no sequence
of messages, mixed with cut and garbled copies."""

from __future__ import annotations

import struct
import zlib
from types import SimpleNamespace

import numpy as np
import pytest
from rosbags.interfaces import Nodetype

from rail_monitor.codec.cdr import CdrError, message_view, serialize
from rail_monitor.codec.cdr_columns import FEW, read_columns
from rail_monitor.codec.typestore import typestore
from rail_monitor.messages.topics import GRAPH_TOPICS

from conftest import random_fields


def _has_message_sequences(typename: str) -> bool:
    for _, (kind, detail) in typestore().fielddefs[typename][1]:
        if kind == Nodetype.NAME and _has_message_sequences(detail):
            return True
        if kind in (Nodetype.ARRAY, Nodetype.SEQUENCE) and detail[0][0] == Nodetype.NAME:
            return True
    return False


COLUMN_TYPES = sorted({t for t, *_ in GRAPH_TOPICS.values() if not _has_message_sequences(t)})


def _row(value, i):
    """Message i of the columns, as the per-message reader gives it."""
    if isinstance(value, SimpleNamespace):
        return SimpleNamespace(**{k: _row(v, i) for k, v in vars(value).items()})
    return value[i]


def _same(got, want) -> bool:
    if isinstance(want, SimpleNamespace):
        return vars(got).keys() == vars(want).keys() and all(_same(getattr(got, k), v) for k, v in vars(want).items())
    if isinstance(want, np.ndarray):
        return got.dtype == want.dtype and got.tobytes() == want.tobytes()
    if isinstance(want, (bool, int, float)):  # a scalar column's item: the same Python type and bits
        item = np.asarray(got).item()
        same = struct.pack("<d", item) == struct.pack("<d", want) if isinstance(want, float) else item == want
        return type(item) is type(want) and same
    return got == want and type(got) is type(want)


def _batch(rng, typename, n, equal_lengths):
    """n messages: random ones (sequences of one length per field when equal_lengths), every
    fourth cut short or garbled."""
    base = random_fields(rng, typename)
    raws = []
    for k in range(n):
        fields = random_fields(rng, typename)
        if equal_lengths:  # each list as long as the first message's (its own values repeated)
            fields = {f: (v * len(base[f]))[:len(base[f])] if isinstance(v, list) and v else
                      base[f] if isinstance(v, list) else v for f, v in fields.items()}
        raw = serialize(typename, fields)
        if k % 4 == 3:
            if rng.random() < 0.5:
                raw = raw[:int(rng.integers(0, len(raw)))]
            else:
                raw = bytearray(raw)
                for i in rng.integers(0, len(raw), 3):
                    raw[i] = int(rng.integers(256))
                raw = bytes(raw)
        raws.append(raw)
    return raws


@pytest.mark.parametrize("equal_lengths", [True, False])
@pytest.mark.parametrize("typename", COLUMN_TYPES)
def test_columns_equal_the_per_message_reader_and_refuse_the_same_bytes(typename, equal_lengths):
    rng = np.random.default_rng(zlib.crc32(typename.encode()) + equal_lengths)
    for n in (1, 2, FEW - 1, FEW, 40):  # read one by one and stacked, then field by field
        raws = _batch(rng, typename, n, equal_lengths)
        want, errors = [], {}
        for i, raw in enumerate(raws):
            try:
                want.append((i, message_view(typename, raw)))
            except CdrError as exc:
                errors[i] = str(exc)
        got = read_columns(typename, raws)
        assert got.index.tolist() == [i for i, _ in want]
        assert {i: str(exc) for i, exc in got.refused} == errors
        for row, (_, view) in enumerate(want):
            assert _same(_row(got.values, row), view), (typename, n, row)


def test_sequences_of_one_length_are_2d_columns():
    typename = "rail_msgs/msg/CorrugationState"
    rng = np.random.default_rng(5)
    fields = [random_fields(rng, typename) for _ in range(3)]
    for f in fields:
        f["amplitude_m"] = rng.random(6).tolist()
    for n in (3, FEW + 3):
        got = read_columns(typename, [serialize(typename, fields[k % 3]) for k in range(n)]).values
        assert got.amplitude_m.shape == (n, 6)
        assert got.k_b_by_friction.shape == (n, 4)
        assert got.header.stamp.sec.shape == (n,)
        np.testing.assert_array_equal(got.amplitude_m, [fields[k % 3]["amplitude_m"] for k in range(n)])


def test_no_bytes_and_empty_bytes():
    typename = "rail_msgs/msg/TrainPass"
    assert len(read_columns(typename, [])) == 0
    for n in (2, FEW):
        got = read_columns(typename, [b"", b"\x00\x01\x00\x00"] * (n // 2))
        assert len(got) == 0 and [i for i, _ in got.refused] == list(range(n))
