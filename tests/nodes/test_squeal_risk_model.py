"""squeal_risk_model in-process: valid passes predicted as the library predicts them, rejections
counted on /diagnostics (rail_monitor.nodes.squeal_risk_model)."""

from __future__ import annotations

import numpy as np
from diagnostic_msgs.msg import DiagnosticArray
from rclpy.node import Node
from rclpy.parameter import Parameter
from squeal.test_predict import _passes

from rail_monitor.messages.fields import train_pass_fields
from rail_monitor.nodes.convert import to_msg
from rail_monitor.nodes.qos import STREAM_QOS
from rail_monitor.nodes.squeal_risk_model import SquealRiskNode
from rail_monitor.squeal.config import squeal_config
from rail_monitor.squeal.predict import predict
from rail_msgs.msg import SquealPrediction, TrainPass

from conftest import spinning, wait_until


def test_node_predicts_valid_passes_and_counts_rejections(ros_context, site, site_values):
    ctx = ros_context
    params = [Parameter(k, value=v) for k, v in site_values.items() if not k.startswith("simulator.")]
    model = SquealRiskNode(context=ctx, namespace="/curve_250", parameter_overrides=params)
    probe = Node("probe", context=ctx, namespace="/curve_250")
    got: list[SquealPrediction] = []
    diags: list[DiagnosticArray] = []
    probe.create_subscription(SquealPrediction, "noise/squeal", got.append, STREAM_QOS)
    probe.create_subscription(DiagnosticArray, "/diagnostics", diags.append, 10)
    pub = probe.create_publisher(TrainPass, "train_pass", STREAM_QOS)
    with spinning(ctx, model, probe):
        wait_until(lambda: pub.get_subscription_count() >= 1)
        good = _passes(site, [3, 8, 12, 16])
        bad = [dict(good.row(0), speed_mps=float("nan"), train_id="nan-speed"),
               dict(good.row(0), friction_state=9, train_id="bad-friction"),
               dict(good.row(0), vehicle_class="tram", train_id="unknown-class"),
               dict(good.row(0), angle_of_attack_rad=0.5, train_id="aoa")]
        for r in [good.row(0), *bad, good.row(1), good.row(2), good.row(3)]:
            pub.publish(to_msg(TrainPass, train_pass_fields(r, "curve_250")))
        wait_until(lambda: len(got) >= 4 and any(_rejected(d) == 4 for d in diags))
    assert [m.train_id for m in got] == ["T0", "T1", "T2", "T3"]
    assert model.taken == 8 and model.accepted.count == 4
    expected = predict(squeal_config(site_values), site, good)
    np.testing.assert_allclose([m.velocity_amplitude_mps for m in got], expected["velocity_amplitude_mps"], rtol=1e-12)
    assert [m.regime for m in got] == list(expected["regime"])
    assert got[0].header.frame_id == "curve_250" and got[0].header.stamp.sec == 1
    status = [s for d in diags for s in d.status if s.name.endswith("squeal_risk_model")][-1]
    values = {kv.key: kv.value for kv in status.values}
    assert values["rejected"] == "4" and values["accepted"] == "4"
    assert values["rejected: speed_mps not finite"] == "1"
    assert values["rejected: friction_state unknown"] == "1"
    assert values["rejected: vehicle_class unknown to the site"] == "1"


def _rejected(d: DiagnosticArray) -> int:
    for s in d.status:
        for kv in s.values:
            if kv.key == "rejected" and s.name.endswith("squeal_risk_model"):
                return int(kv.value)
    return -1
