"""What the nodes publish (rail_monitor.nodes.convert.to_cdr: codec.cdr's bytes, sent as they are)
against rclpy's own serialisation of the message to_msg builds from the same fields."""

from __future__ import annotations

import zlib

import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message

from rail_monitor.core.errors import RailMonitorError
from rail_monitor.messages.topics import GRAPH_TOPICS
from rail_monitor.nodes.convert import TOPICS, message_class, to_cdr, to_msg, typename_of

from conftest import random_fields


@pytest.mark.parametrize("topic", sorted(GRAPH_TOPICS))
def test_published_bytes_are_the_message_rclpy_builds_from_the_fields(topic):
    # Random string and sequence lengths and values (every alignment an offset can take): rclpy
    # reads our bytes as the very message to_msg builds, the message its own bytes of it give (rclpy's
    # buffer may run past the message with stale bytes, so the bytes themselves are not compared).
    cls = TOPICS[topic][0]
    assert typename_of(cls) == GRAPH_TOPICS[topic][0]
    rng = np.random.default_rng(zlib.crc32(topic.encode()) + 2)
    for _ in range(40):
        fields = random_fields(rng, typename_of(cls))
        want = to_msg(cls, fields)
        ours = to_cdr(cls, fields)
        assert deserialize_message(ours, cls) == want
        assert deserialize_message(bytes(serialize_message(want)), cls) == deserialize_message(ours, cls)


def test_numpy_scalars_are_packed_as_rclpy_casts_them():
    # The models' outputs are numpy scalars; to_msg casts them to the field's Python type.
    cls = TOPICS["noise/squeal"][0]
    fields = random_fields(np.random.default_rng(5), typename_of(cls))
    fields.update(speed_mps=np.float64(17.25), unstable=np.bool_(True), regime=np.uint8(2), risk=np.int64(3))
    assert deserialize_message(to_cdr(cls, fields), cls) == to_msg(cls, fields)


def test_a_value_out_of_its_fields_range_is_refused():
    cls = TOPICS["noise/squeal"][0]
    fields = random_fields(np.random.default_rng(6), typename_of(cls))
    with pytest.raises(Exception):  # noqa: B017  (struct.error, as rclpy's own check raises)
        to_cdr(cls, {**fields, "risk": 256})


def test_a_type_that_is_not_installed_is_named_in_one_line():
    for typename in ("nope_msgs/msg/Thing", "rail_msgs/msg/NoSuchMessage"):
        with pytest.raises(RailMonitorError, match=f"message type {typename} is not installed"):
            message_class(typename)
