"""Stamps a builtin_interfaces/Time cannot hold, or before 1970: a rejection or a one-line error,
never a crash, a wrap-around or a stopped node (readers, batch, replayer, recorder, the graph)."""

from __future__ import annotations

import time

import numpy as np
import pytest
from rclpy.node import Node
from rclpy.parameter import Parameter

from rail_monitor.app.batch import run_models, write_bag
from rail_monitor.bagio.csv_io import read_csv
from rail_monitor.bagio.reader import read_bag_passes
from rail_monitor.cli import main
from rail_monitor.core.errors import InputError
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
    """The example CSV with a pass in 2100 and one before 1970 appended."""
    csv = tmp_path / "odd.csv"
    text = EXAMPLE_CSV.read_text()
    row = text.strip().splitlines()[-1].split(",")
    late = ",".join(["2100-01-01T00:00:00Z", "LATE-1", *row[2:]])
    early = ",".join(["1969-12-31T23:59:00Z", "EARLY-1", *row[2:]])
    csv.write_text(text + late + "\n" + early + "\n")
    return csv


def test_batch_rejects_them_counted_and_the_bag_never_wraps_a_stamp(tmp_path, site_values):
    passes = read_csv(_with_odd_stamps(tmp_path))
    result = run_models(passes, site_values)
    reasons = dict(zip(result.passes.train_id.tolist(), result.reasons.tolist(), strict=True))
    # As the replayer: a TrainPass cannot hold the 2100 stamp, so it is left out (counted); the
    # pre-1970 pass is published and rejected with its reason.
    assert result.left_out == 1 and "LATE-1" not in reasons and reasons["EARLY-1"] == "stamp before 1970"
    bag = write_bag(result, tmp_path / "bag", "curve_250")
    recorded = read_bag_passes(bag)
    assert len(recorded) == len(passes) - 1 and recorded.stamp_ns.max() < 2**31 * 10**9
    assert int(recorded.stamp_ns[recorded.train_id == "EARLY-1"][0]) == -60 * 10**9  # the stamp kept, no wrap


def test_the_graph_runs_through_them_and_exits_0(tmp_path, capsys):
    t0 = time.monotonic()
    out = tmp_path / "rec"
    assert main(["monitor", str(_with_odd_stamps(tmp_path)), "--output", str(out), "--no-report"]) == 0
    assert time.monotonic() - t0 < 60
    recorded = read_bag_passes(out)
    assert "EARLY-1" in recorded.train_id.tolist() and "LATE-1" not in recorded.train_id.tolist()
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
