"""Recorder write rate against the bare mcap writer, on the same messages.

The messages are those the graph records for a history (batch mode's bag of the sample:
every topic, serialised CDR). The recorder's work per message is its callback's: the header
stamp read from the CDR bytes (the log time) and McapBagWriter.write (rosbag2 layout, channel
metadata, file rotation checks). The bare writer is mcap's Writer with the same chunk size and
compression, one schema and channel per topic, add_message only.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

from mcap.reader import make_reader
from mcap.writer import CompressionType, Writer

from rail_monitor.bagio.mcap_bag import McapBagWriter
from rail_monitor.codec.typestore import header_stamp_ns, schema_text

CHUNK = 1 << 20  # mcap_recorder's default chunk_size


def recorded_messages(bag: Path) -> tuple[dict[str, str], list[tuple[str, bytes, int]]]:
    """(topic -> type, [(topic, CDR bytes, log time [ns])]) of every .mcap file of a bag folder."""
    types: dict[str, str] = {}
    out: list[tuple[str, bytes, int]] = []
    for path in sorted(bag.glob("*.mcap")):
        with path.open("rb") as f:
            for schema, channel, message in make_reader(f).iter_messages(log_time_order=False):
                types[channel.topic] = schema.name
                out.append((channel.topic, message.data, message.log_time))
    return types, out


def recorder_s(types: dict[str, str], messages: list[tuple[str, bytes, int]], folder: Path) -> float:
    t = time.perf_counter()
    bag = McapBagWriter(folder, compression="zstd", chunk_size=CHUNK)
    for topic, typename in types.items():
        bag.add_topic(topic, typename)
    for topic, data, _ in messages:
        bag.write(topic, data, header_stamp_ns(data))
    bag.close()
    return time.perf_counter() - t


def bare_mcap_s(types: dict[str, str], messages: list[tuple[str, bytes, int]], path: Path) -> float:
    t = time.perf_counter()
    with path.open("wb") as f:
        w = Writer(f, chunk_size=CHUNK, compression=CompressionType.ZSTD)
        w.start(profile="ros2", library="bench")
        ids = {}
        for topic, typename in types.items():
            sid = w.register_schema(name=typename, encoding="ros2msg", data=schema_text(typename).encode())
            ids[topic] = w.register_channel(topic=topic, message_encoding="cdr", schema_id=sid)
        for topic, data, log_time in messages:
            w.add_message(channel_id=ids[topic], log_time=log_time, data=data, publish_time=log_time)
        w.finish()
    return time.perf_counter() - t


def compare(bag: Path, repeat: int = 3) -> dict[str, float]:
    """Messages per second of both writers (best of repeat) and the bytes written."""
    types, messages = recorded_messages(bag)
    best_rec = best_bare = float("inf")
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(repeat):
            best_rec = min(best_rec, recorder_s(types, messages, Path(tmp) / f"rec{i}"))
            best_bare = min(best_bare, bare_mcap_s(types, messages, Path(tmp) / f"bare{i}.mcap"))
    n = len(messages)
    return {"messages": n, "mb": sum(len(d) for _, d, _ in messages) / 1e6, "recorder_per_s": n / best_rec,
            "bare_per_s": n / best_bare}
