"""Messages written together from columns (rail_monitor.codec.cdr_from_columns) against the
per-message writer (rail_monitor.codec.cdr.serialize, itself held to rosbags' bytes): the same
bytes for every message, on random messages of every graph type that has no sequence of
messages (random string and sequence lengths: every alignment an offset can take)."""

from __future__ import annotations

import struct
import zlib

import numpy as np
import pytest

from rail_monitor.codec.cdr import serialize
from rail_monitor.codec.cdr_columns import FEW, read_columns
from rail_monitor.codec.cdr_from_columns import serialize_columns
from tests.codec.test_cdr_columns import COLUMN_TYPES

from conftest import random_fields


@pytest.mark.parametrize("equal_lengths", [True, False])
@pytest.mark.parametrize("typename", COLUMN_TYPES)
def test_bytes_written_together_equal_one_by_one(typename, equal_lengths):
    rng = np.random.default_rng(zlib.crc32(typename.encode()) + 7 * equal_lengths)
    for n in (1, FEW - 1, FEW, 50):
        base = random_fields(rng, typename)
        fields = []
        for _ in range(n):
            f = random_fields(rng, typename)
            if equal_lengths:  # every numeric sequence as long as the first message's
                f = {k: (v * len(base[k]))[:len(base[k])] if isinstance(v, list) and v else base[k]
                     if isinstance(v, list) else v for k, v in f.items()}
            fields.append(f)
        want = [serialize(typename, f) for f in fields]
        columns = read_columns(typename, want).values   # the columns a node reads, in every form
        assert serialize_columns(typename, columns, n) == want


def test_a_missing_column_or_a_fixed_array_of_the_wrong_length_is_refused():
    typename = "rail_msgs/msg/CorrugationState"
    rng = np.random.default_rng(3)
    raws = [serialize(typename, random_fields(rng, typename)) for _ in range(FEW)]
    columns = read_columns(typename, raws).values
    whole = columns.k_b_by_friction
    columns.k_b_by_friction = whole[:, :3]
    with pytest.raises(ValueError, match="k_b_by_friction"):
        serialize_columns(typename, columns, FEW)
    columns.k_b_by_friction = whole
    del columns.calibration_surveys
    with pytest.raises(KeyError, match="calibration_surveys"):
        serialize_columns(typename, columns, FEW)


def test_an_integer_its_field_cannot_hold_is_refused_as_one_message_refuses_it():
    typename = "rail_msgs/msg/TrainPass"
    rng = np.random.default_rng(4)
    raws = [serialize(typename, random_fields(rng, typename)) for _ in range(FEW)]
    for name, bad in (("vehicle_count", 70_000), ("friction_state", -1)):
        columns = read_columns(typename, raws).values
        column = getattr(columns, name).astype(np.int64)
        column[FEW // 2] = bad
        setattr(columns, name, column)
        with pytest.raises(ValueError, match=f"field {name}: a value is outside"):
            serialize_columns(typename, columns, FEW)
        fields = random_fields(rng, typename) | {name: bad}
        with pytest.raises(struct.error):   # the per-message writer: numpy would have wrapped it
            serialize(typename, fields)
