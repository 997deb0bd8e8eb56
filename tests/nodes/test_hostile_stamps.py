"""Stamps a builtin_interfaces/Time cannot hold, or before 1970: a rejection or a one-line error,
never a crash, a wrap-around or a stopped node (readers, batch, replayer, recorder, the graph)."""

from __future__ import annotations

import time

import numpy as np
import pytest
from rclpy.node import Node
from rclpy.parameter import Parameter

from rail_monitor.bagio.csv_io import read_csv
from rail_monitor.bagio.reader import read_bag_passes
from rail_monitor.batch.bag import write_bag
from rail_monitor.batch.run import run_models
from rail_monitor.cli import main
from rail_monitor.core.errors import InputError
from rail_monitor.core.passes import ahead_reason
from rail_monitor.nodes.mcap_recorder import McapRecorder
from rail_monitor.nodes.qos import STREAM_QOS
from rail_msgs.msg import TrainPass

from conftest import EXAMPLE_CSV, spinning, wait_until

HEADER = "time_unix_s,train_id,vehicle_class,vehicle_count,speed_mps,angle_of_attack_rad,friction_state\n"


@pytest.mark.parametrize(("column", "value"), [("time_unix_s", "inf"), ("time_unix_s", "1e20"),
                                               ("time_unix_ns", "1" + "0" * 25), ("time_utc", "9999-12-31T23:59:59Z")])
def test_times_no_int64_can_hold_are_a_malformed_row(tmp_path, column, value):
    csv = tmp_path / "p.csv"
    csv.write_text(f"{column},train_id,vehicle_class,vehicle_count,speed_mps,angle_of_attack_rad,friction_state\n"
                   f"{value},T1,emu,3,19.0,0.005,dry\n")
    with pytest.raises(InputError, match=r"line 2: column .* out of range|line 2: column .* not a finite"):
        read_csv(csv)
    assert len(read_csv(csv, skip_bad_rows=True)) == 0


def _with_odd_stamps(tmp_path):
    """The example CSV with a pass in 2100, one in 2031 (years past the rest) and one before 1970 appended."""
    csv = tmp_path / "odd.csv"
    text = EXAMPLE_CSV.read_text()
    row = text.strip().splitlines()[-1].split(",")
    late = ",".join(["2100-01-01T00:00:00Z", "LATE-1", *row[2:]])
    far = ",".join(["2031-01-01T00:00:00Z", "FAR-1", *row[2:]])
    early = ",".join(["1969-12-31T23:59:00Z", "EARLY-1", *row[2:]])
    csv.write_text(text + late + "\n" + far + "\n" + early + "\n")
    return csv


def test_batch_rejects_them_counted_and_the_bag_never_wraps_a_stamp(tmp_path, site_values):
    passes = read_csv(_with_odd_stamps(tmp_path))
    result = run_models(passes, site_values)
    reasons = dict(zip(result.passes.train_id.tolist(), result.reasons.tolist(), strict=True))
    # As the replayer: a TrainPass cannot hold the 2100 stamp and the 2031 one is years past the
    # stream, so both are left out (counted); the pre-1970 pass is published and rejected with its reason.
    assert result.left_out == {"stamp not representable (builtin_interfaces/Time seconds are int32)": 1,
                               ahead_reason(366 * 86_400.0, "stream"): 1}
    assert "LATE-1" not in reasons and "FAR-1" not in reasons and reasons["EARLY-1"] == "stamp before 1970"
    bag = write_bag(result, tmp_path / "bag", "curve_250")
    recorded = read_bag_passes(bag)
    assert len(recorded) == len(passes) - 2 and recorded.stamp_ns.max() < 2**31 * 10**9
    assert int(recorded.stamp_ns[recorded.train_id == "EARLY-1"][0]) == -60 * 10**9  # the stamp kept, no wrap


def test_the_graph_runs_through_them_and_exits_0(tmp_path, capsys):
    t0 = time.monotonic()
    out = tmp_path / "rec"
    assert main(["monitor", str(_with_odd_stamps(tmp_path)), "--output", str(out), "--no-report"]) == 0
    assert time.monotonic() - t0 < 60
    recorded = read_bag_passes(out)
    assert "EARLY-1" in recorded.train_id.tolist()
    assert "LATE-1" not in recorded.train_id.tolist() and "FAR-1" not in recorded.train_id.tolist()
    capsys.readouterr()


def test_a_negative_stamp_does_not_stop_the_recorder(ros_context, tmp_path):
    rec = McapRecorder(context=ros_context, parameter_overrides=[Parameter("output", value=str(tmp_path / "bag")),
                                                                 Parameter("topics", value=["/train_pass"])])
    pub_node = Node("hostile", context=ros_context)
    pub = pub_node.create_publisher(TrainPass, "/train_pass", STREAM_QOS)
    with spinning(ros_context, rec, pub_node):
        assert wait_until(lambda: pub.get_subscription_count() >= 1, 10)
        for sec in (-5, 1_790_000_000, -(2**31), 1_790_000_001):
            msg = TrainPass(train_id=f"T{sec}")
            msg.header.stamp.sec = sec
            pub.publish(msg)
        assert wait_until(lambda: rec.counts.get("/train_pass", 0) == 4, 10)
    rec.close()
    got = read_bag_passes(tmp_path / "bag")
    assert sorted(got.train_id.tolist()) == sorted(f"T{s}" for s in (-5, 1_790_000_000, -(2**31), 1_790_000_001))
    assert np.all(got.stamp_ns >= -(2**31) * 10**9)
    rec.destroy_node()
    pub_node.destroy_node()


def _estimator(ctx, site_values, **extra):
    from rail_monitor.nodes.corrugation_estimator import CorrugationEstimatorNode

    params = [Parameter(k, value=v) for k, v in {**site_values, **extra}.items() if not k.startswith("simulator.")]
    return CorrugationEstimatorNode(context=ctx, namespace="/curve_250", parameter_overrides=params)


def _send(ctx, node, table, *, sim_time: bool = True):
    """Publish the rows of table to node's train_pass, in order; wait until it took them all."""
    from rail_monitor.messages.fields import train_pass_fields
    from rail_monitor.nodes.convert import to_msg

    pub_node = Node("hostile", context=ctx, namespace="/curve_250")
    pub = pub_node.create_publisher(TrainPass, "train_pass", STREAM_QOS)
    with spinning(ctx, node, pub_node):
        assert wait_until(lambda: pub.get_subscription_count() >= 1, 10)
        for i in range(len(table)):
            pub.publish(to_msg(TrainPass, train_pass_fields(table.row(i), "curve_250")))
        assert wait_until(lambda: node.taken == len(table), 10)
    pub_node.destroy_node()


def _stream(site, stamps_s, ids):
    from rail_monitor.core.passes import FRICTION_DRY, PassTable

    n = len(stamps_s)
    return PassTable(stamp_ns=np.array(stamps_s, dtype=np.int64) * 10**9, train_id=ids, vehicle_class=["emu"] * n,
                     vehicle_count=[4] * n, axle_count=[0] * n, speed_mps=[18.0] * n, angle_of_attack_rad=[0.0] * n,
                     wheel_load_n=[0.0] * n, friction_state=[FRICTION_DRY] * n, train_length_m=[0.0] * n)


def test_one_pass_in_2037_does_not_freeze_the_corrugation_state(ros_context, site, site_values, tmp_path):
    # Issue 21: one 2037 stamp mid-stream made every later real pass "older than the history", and
    # the checkpoint kept it. Now it is rejected with its reason; the passes after it are counted,
    # the checkpoint holds the real stream, and a resumed node judges a first 2037 pass against it.
    t0 = 1_760_000_000  # 2025-10-09, in the past of any clock this runs on
    stamps = [t0 + 600 * k for k in range(6)]
    ids = [f"T{k}" for k in range(6)]
    table = _stream(site, [*stamps[:3], 2_130_000_000, *stamps[3:]], [*ids[:3], "Y2037", *ids[3:]])
    ckpt = tmp_path / "state.npz"
    node = _estimator(ros_context, site_values, use_sim_time=True, checkpoint_path=str(ckpt))
    _send(ros_context, node, table)
    reason = ahead_reason(366 * 86_400.0, "stream")
    assert node.rejected == {reason: 1} and node.counts["counted"] == 6
    assert node.est.newest_ns == stamps[-1] * 10**9
    node.close()
    node.destroy_node()

    resumed = _estimator(ros_context, site_values, use_sim_time=True, checkpoint_path=str(ckpt))
    assert resumed.stream_ns == stamps[-1] * 10**9
    _send(ros_context, resumed, _stream(site, [2_130_000_000, stamps[-1] + 600], ["Y2037", "T6"]))
    assert resumed.rejected == {reason: 1} and resumed.counts["counted"] == 1
    resumed.destroy_node()


def test_a_live_node_rejects_a_pass_ahead_of_its_clock(ros_context, site, site_values):
    # Not on sim time (a detector feeding the graph): a stamp two days ahead of the clock is a
    # rejection; one just behind it is taken.
    now_s = time.time_ns() // 10**9
    node = _estimator(ros_context, site_values, use_sim_time=False)
    _send(ros_context, node, _stream(site, [now_s - 60, now_s + 2 * 86_400, now_s - 30], ["A", "AHEAD", "B"]))
    assert node.rejected == {ahead_reason(86_400.0, "clock"): 1} and node.counts["counted"] == 2
    node.destroy_node()
