"""The compiled CDR encoder (rail_monitor.codec.cdr) against rosbags' serialiser, byte for byte,
and against rclpy's deserialiser, on messages of every type the graph records with random
string lengths, sequence lengths and values (every alignment an offset can take)."""

from __future__ import annotations

import contextlib
import zlib
from types import SimpleNamespace

import numpy as np
import pytest
from rclpy.serialization import deserialize_message
from rosbags.interfaces import Nodetype

from rail_monitor.codec.cdr import serialize
from rail_monitor.codec.typestore import typestore
from rail_monitor.messages.topics import GRAPH_TOPICS
from rail_monitor.nodes.convert import TOPICS

from conftest import random_fields


def _rosbags_message(typename: str, fields: dict):
    """rosbags' message object of these fields: the independent serialiser's input."""
    store = typestore()
    kwargs = {}
    for name, (kind, detail) in store.fielddefs[typename][1]:
        v = fields[name]
        if kind == Nodetype.NAME:
            v = _rosbags_message(detail, v)
        elif kind in (Nodetype.ARRAY, Nodetype.SEQUENCE):
            item_kind, item = detail[0]
            if item_kind == Nodetype.NAME:
                v = [_rosbags_message(item, x) for x in v]
            elif item[0] != "string":
                v = np.asarray(v, dtype=np.dtype(item[0].replace("byte", "uint8").replace("char", "uint8")))
        kwargs[name] = v
    return store.types[typename](**kwargs)


@pytest.mark.parametrize("topic", sorted(GRAPH_TOPICS))
def test_bytes_equal_rosbags_and_decode_with_rclpy(topic):
    typename = GRAPH_TOPICS[topic][0]
    rng = np.random.default_rng(zlib.crc32(topic.encode()))
    for _ in range(60):
        data = random_fields(rng, typename)
        ours = serialize(typename, data)
        assert ours == bytes(typestore().serialize_cdr(_rosbags_message(typename, data), typename))
        deserialize_message(ours, TOPICS[topic][0])  # rclpy reads it whole


def test_missing_fields_are_zero_and_wrong_lengths_are_refused():
    typename = "rail_msgs/msg/CorrugationState"
    full = random_fields(np.random.default_rng(1), typename)
    # Fixed-length arrays left out are zeros, as rclpy and rosbags construct them.
    def zero_of(k, v):
        if k == "k_b_by_friction":
            return v
        if k.startswith("k_b_"):
            return [0.0] * 4
        if not isinstance(v, dict):
            return type(v)()
        return {"sec": 0, "nanosec": 0} if k.endswith("time") else {"stamp": {"sec": 0, "nanosec": 0}, "frame_id": ""}

    zero = {k: zero_of(k, v) for k, v in full.items()}
    assert serialize(typename, {"k_b_by_friction": full["k_b_by_friction"]}) == serialize(typename, zero)
    with pytest.raises(ValueError, match="k_b_by_friction"):
        serialize(typename, {"k_b_by_friction": [1.0, 2.0]})
    with pytest.raises(KeyError, match="no field"):
        serialize(typename, {"header": {"stampp": {}}})


def _same_fields(got, want) -> bool:
    if isinstance(want, dict):
        return got.keys() == want.keys() and all(_same_fields(got[k], v) for k, v in want.items())
    if isinstance(got, np.ndarray):
        return np.array_equal(got, np.asarray(want, dtype=got.dtype))
    if isinstance(want, list):
        return len(got) == len(want) and all(_same_fields(g, w) for g, w in zip(got, want, strict=True))
    return got == want or (want != want and got != got)


def _as_dicts(value):
    if isinstance(value, SimpleNamespace):
        return {k: _as_dicts(v) for k, v in vars(value).items()}
    return [_as_dicts(v) for v in value] if isinstance(value, list) else value


@pytest.mark.parametrize("topic", sorted(GRAPH_TOPICS))
def test_the_decoder_reads_back_ours_and_rclpys_bytes(topic):
    # as dicts, and as the attribute views the nodes read
    from rclpy.serialization import serialize_message

    from rail_monitor.codec.cdr import deserialize, message_view
    from rail_monitor.nodes.convert import to_msg

    typename = GRAPH_TOPICS[topic][0]
    rng = np.random.default_rng(zlib.crc32(topic.encode()) + 1)
    for _ in range(40):
        data = random_fields(rng, typename)
        assert _same_fields(deserialize(typename, serialize(typename, data)), data)
        assert _same_fields(_as_dicts(message_view(typename, serialize(typename, data))), data)
        # rclpy's bytes (its padding is not zeroed) decode to the fields rclpy itself reads back
        theirs = bytes(serialize_message(to_msg(TOPICS[topic][0], data)))
        assert serialize(typename, deserialize(typename, theirs)) == serialize(typename, data)


@pytest.mark.parametrize("topic", ["corrugation/state", "train_pass", "alerts/standing"])
def test_cut_or_garbled_bytes_are_one_cdr_error(topic):
    from rail_monitor.codec.cdr import CdrError, deserialize

    typename = GRAPH_TOPICS[topic][0]
    rng = np.random.default_rng(11)
    whole = serialize(typename, random_fields(rng, typename))
    for cut in range(len(whole) - 4):  # every prefix short of the last padding bytes
        with pytest.raises(CdrError):
            deserialize(typename, whole[:cut])
    for _ in range(300):
        garbled = bytearray(whole)
        for i in rng.integers(4, len(whole), 3):
            garbled[i] = int(rng.integers(256))
        with contextlib.suppress(CdrError):  # any other exception fails the test
            deserialize(typename, bytes(garbled))
