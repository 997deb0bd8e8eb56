"""Message fields (rail_monitor.messages.fields) and their two serialisers: rosbags' CDR
(rail_monitor.codec.cdr, batch mode) and rclpy messages (rail_monitor.nodes.convert, the live
graph) agree field for field for every topic the graph records."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message

from rail_monitor.alerts.manager import Alert
from rail_monitor.codec.cdr import serialize
from rail_monitor.codec.typestore import TRAIN_PASS, typestore
from rail_monitor.messages import fields
from rail_monitor.messages.topics import GRAPH_TOPICS
from rail_monitor.nodes.convert import TOPICS, message_class, to_msg

from conftest import TOP


@pytest.fixture(scope="module")
def outputs(site_values_module):
    from rail_monitor.bagio.reader import read_passes
    from rail_monitor.batch.run import run_models

    return run_models(read_passes(TOP / "bags" / "example_passes.csv"), site_values_module)


@pytest.fixture(scope="module")
def site_values_module():
    from rail_monitor.site_file import load_parameter_file

    from conftest import SITE_FILE

    return load_parameter_file(SITE_FILE)


def _cases(r) -> dict[str, dict]:
    """One message's fields per graph topic, from a real batch run."""
    frame = r.site.site_id
    tp = fields.train_pass_fields(r.accepted.row(3), frame)
    snap, fc = r.trajectory.state(3)
    alert = Alert(5, "train_pass", 1, True, "x", 0.25, 0.05, "-", 10**18, 10**18, 3 * 10**18)
    return {
        "train_pass": tp,
        "noise/squeal": fields.squeal_prediction_fields(r.squeal, 3, tp["header"], tp["train_id"]),
        "corrugation/state": fields.corrugation_state_fields(snap, fc, frame),
        "noise/rolling": fields.rolling_noise_fields(r.noise["cnossos"], 3, tp["header"], tp["train_id"],
                                                     r.receiver),
        "alerts": fields.wayside_alert_fields(alert, frame),
        "alerts/standing": fields.wayside_alert_array_fields([alert, alert], 10**18, frame),
        "speed_advisory": fields.speed_advisory_fields(r.advice, r.estimator.newest_ns, frame),
    }


@pytest.mark.parametrize("topic", sorted(GRAPH_TOPICS))
def test_rosbags_cdr_decodes_with_rclpy_to_the_rclpy_message_of_the_same_fields(outputs, topic):
    data = _cases(outputs)[topic]
    typename, _ = GRAPH_TOPICS[topic]
    cls = TOPICS[topic][0]
    built = to_msg(cls, data)
    assert _same(deserialize_message(serialize(typename, data), cls), built)
    # and rclpy's bytes decode with rosbags to the same values (padding bytes aside, CDR is one format)
    back = typestore().deserialize_cdr(serialize_message(built), typename)
    assert serialize(typename, _fields_of(back)) == serialize(typename, data)


def _same(a, b) -> bool:
    """rclpy messages equal field by field, NaN equal to NaN."""
    if hasattr(a, "get_fields_and_field_types"):
        return type(a) is type(b) and all(_same(getattr(a, k), getattr(b, k)) for k in a.get_fields_and_field_types())
    if isinstance(a, str):
        return a == b
    if hasattr(a, "__len__"):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return a == b or (a != a and b != b)


def _fields_of(msg) -> dict:
    """A rosbags message object as plain fields (arrays as lists; the type's fields, not its constants)."""
    out = {}
    for name, _ in typestore().fielddefs[msg.__msgtype__][1]:
        v = getattr(msg, name)
        if hasattr(v, "__dataclass_fields__"):
            v = _fields_of(v)
        elif isinstance(v, list):
            v = [_fields_of(x) if hasattr(x, "__dataclass_fields__") else x for x in v]
        elif isinstance(v, np.ndarray):
            v = v.tolist()
        out[name] = v
    return out


def test_train_pass_fields_round_trip_a_table_row(sample_passes):
    for i in range(0, len(sample_passes), 1009):
        row = sample_passes.row(i)
        msg = typestore().deserialize_cdr(serialize("rail_msgs/msg/TrainPass", fields.train_pass_fields(row, "s")),
                                          "rail_msgs/msg/TrainPass")
        assert fields.pass_row(msg) == row


def test_times_past_2038_are_never_and_unknown_fields_are_refused():
    assert fields.future_time_fields(2**31 * 10**9) == {"sec": 0, "nanosec": 0}
    assert fields.future_time_fields(2**31 * 10**9 - 1) == {"sec": 2**31 - 1, "nanosec": 999_999_999}
    with pytest.raises(KeyError, match="no field"):
        serialize("rail_msgs/msg/TrainPass", {"train_idd": "x"})
    assert message_class("rail_msgs/msg/TrainPass").__name__ == "TrainPass"


def test_outputs_as_columns_are_the_bytes_of_each_outputs_fields(outputs):
    # the columns a node publishes a backlog's outputs from, written together (codec.cdr_from_columns),
    # against each pass's fields written alone: every model, every pass of a real run
    from rail_monitor.codec.cdr_from_columns import serialize_columns

    r = outputs
    heads = []
    for i in range(len(r.accepted)):
        tp = fields.train_pass_fields(r.accepted.row(i), r.site.site_id)
        heads.append(fields.PassHead(0, tp["header"], tp["train_id"]))
    n = len(heads)
    assert n > 20
    # a node's heads (taken from the TrainPasses it read) and batch's (from the table it sent)
    for head in (fields.heads_columns(heads), fields.table_heads_columns(r.accepted, r.site.site_id)):
        for model, out in r.noise.items():
            columns = fields.rolling_noise_columns(out, head, r.receiver)
            got = serialize_columns("rail_msgs/msg/RollingNoise", columns, n)
            assert got == [serialize("rail_msgs/msg/RollingNoise", fields.rolling_noise_fields(
                out, i, heads[i].header, heads[i].train_id, r.receiver)) for i in range(n)], model
        got = serialize_columns("rail_msgs/msg/SquealPrediction", fields.squeal_prediction_columns(r.squeal, head), n)
        assert got == [serialize("rail_msgs/msg/SquealPrediction", fields.squeal_prediction_fields(
            r.squeal, i, heads[i].header, heads[i].train_id)) for i in range(n)]
    # every pass sent, the rejected ones included
    got = serialize_columns(TRAIN_PASS, fields.train_pass_columns(r.passes, "s"), len(r.passes))
    assert got == [serialize(TRAIN_PASS, fields.train_pass_fields(r.passes.row(i), "s")) for i in range(len(r.passes))]
    # states: with the constants changed part way (as a survey or a grinding changes them)
    traj, site = r.trajectory, r.site.site_id
    later = dataclasses.replace(traj.constants, threshold=traj.constants.threshold * 2, calibration_surveys=3,
                                k_b=traj.constants.k_b * 1.5, last_grinding_ns=traj.constants.last_grinding_ns + 7)
    for t in (traj, dataclasses.replace(traj, constants_from=((len(traj) // 3, later),))):
        got = [b for cols, m in fields.corrugation_state_columns(t, site)
               for b in serialize_columns("rail_msgs/msg/CorrugationState", cols, m)]
        assert got == [serialize("rail_msgs/msg/CorrugationState", fields.corrugation_state_fields(*t.state(k), site))
                       for k in range(len(t))]
