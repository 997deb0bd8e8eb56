"""Squeal at the site: per-pass prediction, the squeal_risk_model node, the predict command."""

from __future__ import annotations

import json

import numpy as np
import pytest
from diagnostic_msgs.msg import DiagnosticArray
from rclpy.node import Node
from rclpy.parameter import Parameter

from rail_monitor import squeal_risk
from rail_monitor.errors import ConfigError
from rail_monitor.models.squeal import REGIME_LIMIT_CYCLE, REGIME_STABLE
from rail_monitor.nodes.convert import train_pass_msg
from rail_monitor.nodes.qos import STREAM_QOS
from rail_monitor.nodes.squeal_risk_model import SquealRiskModel
from rail_monitor.passes import FRICTION_DRY, FRICTION_MODIFIER, PassTable, rejection_reasons, with_class_defaults
from rail_monitor.site import site_from_values
from rail_msgs.msg import SquealPrediction, TrainPass

from conftest import run_cmd, spinning, wait_until


def _passes(site, aoa_mrad, friction=FRICTION_DRY, speed=19.0) -> PassTable:
    aoa = np.atleast_1d(np.asarray(aoa_mrad, float)) * 1e-3
    n = len(aoa)
    return with_class_defaults(PassTable(
        stamp_ns=np.arange(1, n + 1) * 10**9, train_id=[f"T{i}" for i in range(n)], vehicle_class=["emu"] * n,
        vehicle_count=[4] * n, axle_count=[0] * n, speed_mps=[speed] * n, angle_of_attack_rad=aoa,
        wheel_load_n=[0.0] * n, friction_state=np.broadcast_to(friction, n), train_length_m=[0.0] * n), site)


def test_site_onset_follows_the_rule_of_thumb(site, site_values):
    # MODELS.md section 1: squeal onset at an angle of attack of about 5-10 mrad (dry rail).
    cfg = squeal_risk.squeal_config(site_values)
    aoa = np.linspace(0.5, 25, 50)
    pred = squeal_risk.predict(cfg, site, _passes(site, aoa))
    onset = aoa[np.argmax(pred["unstable"])]
    assert 5.0 <= onset <= 10.0
    assert np.all(pred["unstable"][aoa > onset])
    assert np.all(pred["regime"][pred["unstable"]] == REGIME_LIMIT_CYCLE)


def test_friction_modifier_removes_squeal_and_its_benefit_is_in_the_field_range(site, site_values):
    cfg = squeal_risk.squeal_config(site_values)
    fm = squeal_risk.predict(cfg, site, _passes(site, [8, 12, 20], FRICTION_MODIFIER))
    assert np.all(fm["regime"] == REGIME_STABLE) and np.all(fm["risk"] == squeal_risk.RISK_NONE)
    np.testing.assert_array_equal(fm["friction_modifier_benefit_db"], 0.0)
    # Eadie & Santoro (2006): 6.3-22.8 dB(A) less curve noise with a friction modifier. Dry
    # passes that squeal at 10-16 mrad land inside that range (against an 80 dB(A) background;
    # a 20 mrad pass would gain 25 dB, more than any site measured).
    dry = squeal_risk.predict(cfg, site, _passes(site, [10, 12, 16]))
    assert np.all(dry["unstable"])
    assert np.all((dry["friction_modifier_benefit_db"] >= 6.3) & (dry["friction_modifier_benefit_db"] <= 22.8))
    assert np.all(np.diff(dry["level_dba"]) > 0)


def test_unknown_or_inconsistent_squeal_parameters_are_refused(site_values):
    with pytest.raises(ConfigError, match=r"squeal\.modal_mas"):
        squeal_risk.squeal_config({**site_values, "squeal.modal_mas": 1.0})
    with pytest.raises(ConfigError, match="risk_high_dba"):
        squeal_risk.squeal_config({**site_values, "squeal.risk_high_dba": 50.0})
    with pytest.raises(ConfigError, match=r"squeal\.poisson_ratio"):  # the contact is the site's, not squeal's
        squeal_risk.squeal_config({**site_values, "squeal.poisson_ratio": 0.3})
    with pytest.raises(ConfigError, match=r"contact.poisson_ratio.*\[0, 0.5\]"):
        site_from_values({**site_values, "contact.poisson_ratio": 0.7})
    with pytest.raises(ConfigError, match=r"contact\.rail_head_radius"):
        site_from_values({**site_values, "contact.rail_head_radius": 0.3})


def test_batch_prediction_of_the_sample_is_fast_and_complete(site, site_values, sample_passes):
    table = sample_passes.take(rejection_reasons(sample_passes, site) == "")
    pred = squeal_risk.predict(squeal_risk.squeal_config(site_values), site, with_class_defaults(table, site))
    assert all(len(v) == len(table) for v in pred.values())
    assert np.all(np.isfinite(pred["velocity_amplitude_mps"]))
    # the sample's friction-modifier passes never squeal; some dry ones do
    fm = table.friction_state == FRICTION_MODIFIER
    assert not np.any(pred["unstable"][fm])
    dry = table.friction_state == FRICTION_DRY
    assert 0.05 < np.mean(pred["unstable"][dry]) < 0.6
    # the mean friction-modifier benefit over the squealing dry passes lies in Eadie & Santoro's
    # 6.3-22.8 dB(A) site range (their mean: 12 dB(A))
    assert 6.3 <= np.mean(pred["friction_modifier_benefit_db"][dry & pred["unstable"]]) <= 22.8


def test_node_predicts_valid_passes_and_counts_rejections(ros_context, site, site_values):
    ctx = ros_context
    params = [Parameter(k, value=v) for k, v in site_values.items() if not k.startswith("simulator.")]
    model = SquealRiskModel(context=ctx, namespace="/curve_250", parameter_overrides=params)
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
            pub.publish(train_pass_msg(r, "curve_250"))
        wait_until(lambda: len(got) >= 4 and any(_rejected(d) == 4 for d in diags))
    assert [m.train_id for m in got] == ["T0", "T1", "T2", "T3"]
    assert model.taken == 8 and model.accepted.count == 4
    expected = squeal_risk.predict(squeal_risk.squeal_config(site_values), site, good)
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


def test_predict_squeal_command_reproduces_the_rig(tmp_path):
    png = tmp_path / "sweep.png"
    r = run_cmd("rail-monitor", "predict", "squeal", "--rig", "--crabbing", "0.39", "--json")
    assert r.returncode == 0, r.stderr
    row = json.loads(r.stdout)["rows"][0]
    assert row["velocity_amplitude_mps"] == pytest.approx(0.33, rel=0.03)
    r = run_cmd("rail-monitor", "predict", "squeal", "--rig", "--sweep", "0.05", "0.5", "10", "--plot", str(png))
    assert r.returncode == 0, r.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    assert "stable" in r.stdout and "limit cycle" in r.stdout
    r = run_cmd("rail-monitor", "predict", "squeal", "--rig", "--load", "2000")
    assert r.returncode == 2 and "error" in r.stderr and "Traceback" not in r.stderr
