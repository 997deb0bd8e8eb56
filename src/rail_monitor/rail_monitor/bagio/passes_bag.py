"""Write a pass history (and its surveys and grinding events) straight into a rosbag2 MCAP bag
(no ROS graph needed)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from rail_monitor.bagio.cdr import serialize
from rail_monitor.bagio.mcap_bag import McapBagWriter
from rail_monitor.bagio.messages import roughness_survey_fields, train_pass_fields
from rail_monitor.bagio.topics import EVENT, STREAM
from rail_monitor.bagio.typestore import ROUGHNESS_SURVEY, TRAIN_PASS
from rail_monitor.core.passes import PassTable
from rail_monitor.corrugation.surveys import MaintenanceEvent


def pass_cdr(table: PassTable, frame_id: str) -> list[bytes]:
    """CDR bytes of a TrainPass per row."""
    return [serialize(TRAIN_PASS, train_pass_fields(table.row(i), frame_id)) for i in range(len(table))]


def write_passes_bag(table: PassTable, folder: str | Path, frame_id: str, topic: str = "/train_pass",
                     chunk_size: int = 1 << 20, events: Sequence[MaintenanceEvent] = ()) -> Path:
    """Write every pass as a TrainPass on topic, and each event as a RoughnessSurvey on
    roughness_survey beside it, log time = stamp; returns the bag folder."""
    with McapBagWriter(folder, chunk_size=chunk_size) as bag:
        bag.add_topic(topic, TRAIN_PASS, [STREAM.as_metadata()])
        for stamp, data in zip(table.stamp_ns, pass_cdr(table, frame_id), strict=True):
            bag.write(topic, data, int(stamp))
        if events:
            survey_topic = topic.rsplit("/", 1)[0] + "/roughness_survey"
            bag.add_topic(survey_topic, ROUGHNESS_SURVEY, [EVENT.as_metadata()])
            for e in events:
                bag.write(survey_topic, serialize(ROUGHNESS_SURVEY, roughness_survey_fields(e, frame_id)),
                          max(e.stamp_ns, 0))
    return Path(folder)
