"""Write a pass history straight into a rosbag2 MCAP bag (no ROS graph needed)."""

from __future__ import annotations

from pathlib import Path

from rail_monitor.bagio.mcap_bag import McapBagWriter, qos_dict
from rail_monitor.bagio.typestore import TRAIN_PASS, typestore
from rail_monitor.passes import PassTable
from rail_monitor.timeutil import to_sec_nanosec


def pass_cdr(table: PassTable, frame_id: str) -> list[bytes]:
    """CDR bytes of a TrainPass per row (rosbags serialiser, identical to rclpy's)."""
    ts = typestore()
    msg_t, header_t, time_t = (ts.types[n] for n in (TRAIN_PASS, "std_msgs/msg/Header", "builtin_interfaces/msg/Time"))
    out = []
    for i in range(len(table)):
        r = table.row(i)
        sec, nanosec = to_sec_nanosec(r.pop("stamp_ns"))
        msg = msg_t(header=header_t(stamp=time_t(sec=sec, nanosec=nanosec), frame_id=frame_id), **r)
        out.append(bytes(ts.serialize_cdr(msg, TRAIN_PASS)))
    return out


def write_passes_bag(table: PassTable, folder: str | Path, frame_id: str, topic: str = "/train_pass",
                     chunk_size: int = 1 << 20) -> Path:
    """Write every pass as a TrainPass on topic, log time = pass time; returns the bag folder."""
    with McapBagWriter(folder, chunk_size=chunk_size) as bag:
        bag.add_topic(topic, TRAIN_PASS, [qos_dict(reliable=True, depth=1000)])
        for stamp, data in zip(table.stamp_ns, pass_cdr(table, frame_id), strict=True):
            bag.write(topic, data, int(stamp))
    return Path(folder)
