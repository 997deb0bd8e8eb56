"""Write a pass history (and its surveys and grinding events) straight into a rosbag2 MCAP bag
(no ROS graph needed)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from rail_monitor.bagio.mcap_bag import McapBagWriter
from rail_monitor.codec.cdr import serialize
from rail_monitor.codec.cdr_from_columns import serialize_columns
from rail_monitor.codec.typestore import FRICTION_APPLICATOR, MEASURED_PASS_NOISE, ROUGHNESS_SURVEY, TRAIN_PASS
from rail_monitor.core.friction import ApplicatorEvent
from rail_monitor.core.passes import PassTable
from rail_monitor.corrugation.surveys import MaintenanceEvent
from rail_monitor.measured.records import Measurement
from rail_monitor.messages.event_fields import friction_applicator_fields, roughness_survey_fields
from rail_monitor.messages.fields import measured_pass_noise_fields, train_pass_columns
from rail_monitor.messages.topics import EVENT, STREAM


def pass_cdr(table: PassTable, frame_id: str) -> list[bytes]:
    """CDR bytes of a TrainPass per row, written together from the table's columns."""
    return serialize_columns(TRAIN_PASS, train_pass_columns(table, frame_id), len(table))


def write_passes_bag(table: PassTable, folder: str | Path, frame_id: str, topic: str = "/train_pass",
                     chunk_size: int = 1 << 20, events: Sequence[MaintenanceEvent] = (),
                     measurements: Sequence[Measurement] = (), applicators: Sequence[ApplicatorEvent] = ()) -> Path:
    """Write every pass as a TrainPass on topic, each event as a RoughnessSurvey on
    roughness_survey, each measurement as a MeasuredPassNoise on noise/measured and each applicator
    start or stop as a FrictionApplicator on friction_applicator beside it, log time = stamp;
    returns the bag folder."""
    with McapBagWriter(folder, chunk_size=chunk_size) as bag:
        bag.add_topic(topic, TRAIN_PASS, [STREAM.as_metadata()])
        bag.write_many(topic, pass_cdr(table, frame_id), table.stamp_ns.tolist())
        ns = topic.rsplit("/", 1)[0]
        for name, typename, qos, items, to_fields in (
                ("roughness_survey", ROUGHNESS_SURVEY, EVENT, events, roughness_survey_fields),
                ("noise/measured", MEASURED_PASS_NOISE, STREAM, measurements, measured_pass_noise_fields),
                ("friction_applicator", FRICTION_APPLICATOR, STREAM, applicators, friction_applicator_fields)):
            if items:
                bag.add_topic(f"{ns}/{name}", typename, [qos.as_metadata()])
            for item in items:
                bag.write(f"{ns}/{name}", serialize(typename, to_fields(item, frame_id)), max(item.stamp_ns, 0))
    return Path(folder)


def write_survey_bag(events: Sequence[MaintenanceEvent], folder: str | Path, frame_id: str,
                     topic: str = "/roughness_survey") -> Path:
    """Write surveys or grinding events alone, each a RoughnessSurvey on topic, log time = stamp
    (rail-monitor batch --surveys and pass_replayer's surveys_source take them); returns the folder."""
    with McapBagWriter(folder) as bag:
        bag.add_topic(topic, ROUGHNESS_SURVEY, [EVENT.as_metadata()])
        for e in events:
            bag.write(topic, serialize(ROUGHNESS_SURVEY, roughness_survey_fields(e, frame_id)), max(e.stamp_ns, 0))
    return Path(folder)
