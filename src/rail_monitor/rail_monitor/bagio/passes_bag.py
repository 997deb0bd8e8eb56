"""Write a pass history straight into a rosbag2 MCAP bag (no ROS graph needed)."""

from __future__ import annotations

from pathlib import Path

from rail_monitor.bagio.cdr import serialize
from rail_monitor.bagio.mcap_bag import McapBagWriter
from rail_monitor.bagio.messages import train_pass_fields
from rail_monitor.bagio.topics import STREAM
from rail_monitor.bagio.typestore import TRAIN_PASS
from rail_monitor.core.passes import PassTable


def pass_cdr(table: PassTable, frame_id: str) -> list[bytes]:
    """CDR bytes of a TrainPass per row."""
    return [serialize(TRAIN_PASS, train_pass_fields(table.row(i), frame_id)) for i in range(len(table))]


def write_passes_bag(table: PassTable, folder: str | Path, frame_id: str, topic: str = "/train_pass",
                     chunk_size: int = 1 << 20) -> Path:
    """Write every pass as a TrainPass on topic, log time = pass time; returns the bag folder."""
    with McapBagWriter(folder, chunk_size=chunk_size) as bag:
        bag.add_topic(topic, TRAIN_PASS, [STREAM.as_metadata()])
        for stamp, data in zip(table.stamp_ns, pass_cdr(table, frame_id), strict=True):
            bag.write(topic, data, int(stamp))
    return Path(folder)
