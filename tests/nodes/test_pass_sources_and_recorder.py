"""Nodes in-process, each test on a fresh Context: replayer -> recorder round trip and more."""

from __future__ import annotations

import threading
import time
from itertools import pairwise
from pathlib import Path

import pytest
import yaml
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import Parameter
from rosbags.highlevel import AnyReader

from rail_monitor.bagio.reader import read_bag_passes
from rail_monitor.codec.typestore import TRAIN_PASS, type_hash
from rail_monitor.core.errors import ConfigError
from rail_monitor.nodes.mcap_recorder import McapRecorder
from rail_monitor.nodes.pass_replayer import PassReplayer
from rail_monitor.nodes.pass_simulator import PassSimulator
from rail_monitor.site_file import load_parameter_file

from conftest import EXAMPLE_CSV, SAMPLE, SITE_FILE


def _params(**kw) -> list[Parameter]:
    return [Parameter(k, value=v) for k, v in kw.items()]


def _site_params(**simulator) -> list[Parameter]:
    """The shipped site file as parameter overrides, with simulator.* values replaced."""
    flat = load_parameter_file(SITE_FILE)
    flat.update({f"simulator.{k}": v for k, v in simulator.items()})
    return [Parameter(k, value=v) for k, v in flat.items()]


def _replay_and_record(ctx, out: Path, source: str, **replay_params):
    """Host a replayer and a recorder on one executor; replay; wait for the recorder; close."""
    rec = McapRecorder(context=ctx, namespace="/site", parameter_overrides=_params(output=str(out)))
    rep = PassReplayer(context=ctx, namespace="/site", parameter_overrides=_params(
        source=source, progress=False, wait_for_subscribers=1, site_id="curve_250", **replay_params))
    topic = rep.pub.topic_name
    rep.consumed = lambda: rec.counts.get(topic, 0)
    ex = SingleThreadedExecutor(context=ctx)
    ex.add_node(rec)
    ex.add_node(rep)
    spin = threading.Thread(target=ex.spin, daemon=True)
    spin.start()
    try:
        n = rep.run()
        deadline = time.monotonic() + 30
        while rec.counts.get(topic, 0) < n and time.monotonic() < deadline:
            time.sleep(0.01)
        rec.close()
    finally:
        ex.shutdown(timeout_sec=2)
        rep.destroy_node()
        rec.destroy_node()
    return n, rec.counts


def test_replayer_to_recorder_round_trip(tmp_path: Path, ros_context):
    source = read_bag_passes(SAMPLE)
    end = 5 * 86400.0  # five days: ~500 passes, enough to cross chunk and batch boundaries
    n, counts = _replay_and_record(ros_context, tmp_path / "rt", str(SAMPLE), end_offset_s=end)
    expected = source.take(source.stamp_ns <= source.stamp_ns[0] + int(end * 1e9))
    assert n == len(expected) > 300
    assert counts["/site/train_pass"] == n
    # every field equal, through DDS and back out of the recorded bag
    assert read_bag_passes(tmp_path / "rt").equals(expected)
    with AnyReader([tmp_path / "rt"]) as r:
        conn = next(c for c in r.connections if c.topic == "/site/train_pass")
        assert conn.msgcount == n and conn.digest == type_hash(TRAIN_PASS)
        diag = [c for c in r.connections if c.topic == "/diagnostics"]
        assert diag and diag[0].msgtype == "diagnostic_msgs/msg/DiagnosticArray"
    with open(next((tmp_path / "rt").glob("*.mcap")), "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        frames = {m.header.frame_id for _, ch, _, m in reader.iter_decoded_messages(topics=["/site/train_pass"])}
        channels = {c.topic: c for c in reader.get_summary().channels.values()}
    assert frames == {"curve_250"}
    ch = channels["/site/train_pass"]
    assert ch.metadata["topic_type_hash"] == type_hash(TRAIN_PASS)
    qos = yaml.safe_load(ch.metadata["offered_qos_profiles"])
    # as discovered from the replayer's publisher (history and depth are not shared by DDS)
    assert (qos[0]["reliability"], qos[0]["durability"], qos[0]["history"]) == ("reliable", "transient_local",
                                                                              "unknown")


def test_csv_replay(tmp_path: Path, ros_context):
    n, counts = _replay_and_record(ros_context, tmp_path / "csv", str(EXAMPLE_CSV))
    from rail_monitor.bagio.csv_io import read_csv

    assert n == len(read_csv(EXAMPLE_CSV)) == counts["/site/train_pass"]
    assert read_bag_passes(tmp_path / "csv").equals(read_csv(EXAMPLE_CSV).sorted())


def test_timed_replay_publishes_clock_on_pass_time(tmp_path: Path, ros_context):
    from rosgraph_msgs.msg import Clock

    # 2 days of history at 2 days per second: about 1 s of wall time, with /clock ticks between passes.
    listener = __import__("rclpy").create_node("clock_listener", context=ros_context)
    ticks: list[int] = []
    listener.create_subscription(Clock, "/clock", lambda m: ticks.append(m.clock.sec * 10**9 + m.clock.nanosec), 100)
    rep = PassReplayer(context=ros_context, parameter_overrides=_params(
        source=str(SAMPLE), progress=False, end_offset_s=2 * 86400.0, rate=2 * 86400.0, clock_period_s=0.02,
        wait_for_subscribers=0))  # only /clock is listened to
    ex = SingleThreadedExecutor(context=ros_context)
    ex.add_node(listener)
    ex.add_node(rep)
    threading.Thread(target=ex.spin, daemon=True).start()
    t0 = time.monotonic()
    n = rep.run()
    wall = time.monotonic() - t0
    time.sleep(0.2)
    ex.shutdown(timeout_sec=2)
    assert n > 150
    assert 0.7 < wall < 3.0  # recorded timing scaled by the rate (first pass to last < 2 days)
    assert len(ticks) > n  # ticks between passes, not only at them
    assert all(b >= a for a, b in pairwise(ticks))  # pass time never runs backwards


def test_simulator_node_writes_bag(tmp_path: Path, ros_context):
    from rail_monitor.site_file import load_parameter_file

    from conftest import SITE_FILE

    flat = load_parameter_file(SITE_FILE)
    flat["simulator.days"] = 3.0
    over = [Parameter(k, value=v) for k, v in flat.items()]
    over += _params(mode="bag", output=str(tmp_path / "sim"), progress=False)
    sim = PassSimulator(context=ros_context, parameter_overrides=over)
    n = sim.run()
    sim.destroy_node()
    assert n == len(read_bag_passes(tmp_path / "sim")) > 200


@pytest.mark.parametrize(
    ("name", "value", "message"),
    [
        ("rate", -1.0, "parameter 'rate'"),
        ("rate", "fast", "parameter 'rate'"),
        ("ack_batch", 5000, "parameter 'ack_batch'"),
    ],
)
def test_bad_parameters_name_the_parameter_and_range(ros_context, name, value, message):
    with pytest.raises(ConfigError) as err:
        PassReplayer(context=ros_context, parameter_overrides=_params(source=str(SAMPLE), **{name: value}))
    assert message in str(err.value) and "allowed" in str(err.value)


def test_unknown_brake_type_is_refused(ros_context):
    from rail_monitor.site_file import load_parameter_file

    from conftest import SITE_FILE

    flat = load_parameter_file(SITE_FILE)
    flat["vehicle.emu.brake_type"] = "magnetic"
    with pytest.raises(ConfigError, match=r"vehicle.emu.brake_type.*'magnetic' is not one of"):
        PassSimulator(context=ros_context, parameter_overrides=[Parameter(k, value=v) for k, v in flat.items()])


def test_simulator_publishes_live_into_the_recorder(tmp_path: Path, ros_context):
    over = _site_params(days=2.0) + _params(progress=False, wait_for_subscribers=1)
    rec = McapRecorder(context=ros_context, parameter_overrides=_params(output=str(tmp_path / "live")))
    sim = PassSimulator(context=ros_context, parameter_overrides=over)
    sim.consumed = lambda: rec.counts.get("/train_pass", 0)
    ex = SingleThreadedExecutor(context=ros_context)
    ex.add_node(rec)
    ex.add_node(sim)
    threading.Thread(target=ex.spin, daemon=True).start()
    n = sim.run()
    deadline = time.monotonic() + 30
    while rec.counts.get("/train_pass", 0) < n and time.monotonic() < deadline:
        time.sleep(0.01)
    rec.close()
    ex.shutdown(timeout_sec=2)
    assert n > 150
    assert read_bag_passes(tmp_path / "live").equals(sim.passes())


def test_train_pass_message_conversion_round_trips(sample_passes):
    from rail_monitor.messages.fields import pass_row, train_pass_fields
    from rail_monitor.nodes.convert import to_msg
    from rail_msgs.msg import TrainPass

    for i in range(0, len(sample_passes), 997):
        row = sample_passes.row(i)
        msg = to_msg(TrainPass, train_pass_fields(row, "curve_250"))
        assert msg.header.frame_id == "curve_250" and pass_row(msg) == row
