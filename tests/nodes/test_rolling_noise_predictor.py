"""rolling_noise_predictor in-process over real DDS: both models per pass, rejected passes and states on
/diagnostics, and a grown corrugation state raising the predicted level."""

from __future__ import annotations

import numpy as np
from diagnostic_msgs.msg import DiagnosticArray
from rclpy.node import Node
from rclpy.parameter import Parameter

from rail_monitor.core.passes import FRICTION_DRY, PassTable, with_class_defaults
from rail_monitor.messages.fields import train_pass_fields
from rail_monitor.models.corrugation_bands import band_limits, wavelength_bands
from rail_monitor.nodes.convert import time_msg, to_msg
from rail_monitor.nodes.qos import STATE_QOS, STREAM_QOS
from rail_monitor.nodes.rolling_noise_predictor import RollingNoisePredictor
from rail_monitor.noise.config import noise_config
from rail_monitor.noise.predict import RollingNoiseModel
from rail_msgs.msg import CorrugationState, RollingNoise, TrainPass

from conftest import spinning, wait_until


def _row(i: int, speed: float = 20.0, **change) -> dict:
    row = {"stamp_ns": (1_790_000_000 + 600 * i) * 10**9, "train_id": f"T{i}", "vehicle_class": "emu",
           "vehicle_count": 4, "axle_count": 0, "speed_mps": speed, "angle_of_attack_rad": 0.0, "wheel_load_n": 0.0,
           "friction_state": FRICTION_DRY, "train_length_m": 0.0}
    row.update(change)
    return row


def _state(amplitude_factor: float) -> CorrugationState:
    bands = wavelength_bands(0.01, 1.0)
    post = 0.5 * band_limits(bands)
    return CorrugationState(header=CorrugationState().header, wavelength_m=bands.tolist(),
                            amplitude_m=(amplitude_factor * post).tolist(), post_grinding_m=post.tolist())


class Probe:
    def __init__(self, ctx) -> None:
        self.node = Node("probe", context=ctx, namespace="/curve_250")
        self.noise: list[RollingNoise] = []
        self.diags: list[DiagnosticArray] = []
        self.node.create_subscription(RollingNoise, "noise/rolling", self.noise.append, STREAM_QOS)
        self.node.create_subscription(DiagnosticArray, "/diagnostics", self.diags.append, 10)
        self.passes = self.node.create_publisher(TrainPass, "train_pass", STREAM_QOS)
        self.states = self.node.create_publisher(CorrugationState, "corrugation/state", STATE_QOS)

    def diag(self) -> dict[str, str]:
        for d in reversed(self.diags):
            for s in d.status:
                if s.name.endswith("rolling_noise_predictor"):
                    return {kv.key: kv.value for kv in s.values}
        return {}


def test_node_publishes_both_models_rejects_bad_input_and_follows_the_corrugation(ros_context, site_values, site):
    params = [Parameter(k, value=v) for k, v in site_values.items() if not k.startswith("simulator.")]
    # state_wait_s 0: each pass takes the latest state at once (the wait is tested in test_graph).
    node = RollingNoisePredictor(context=ros_context, namespace="/curve_250",
                                 parameter_overrides=[*params, Parameter("state_wait_s", value=0.0)])
    probe = Probe(ros_context)
    with spinning(ros_context, node, probe.node):
        assert wait_until(lambda: probe.passes.get_subscription_count() >= 1 and probe.node.count_publishers(
            "/curve_250/noise/rolling") >= 1)
        probe.passes.publish(to_msg(TrainPass, train_pass_fields(_row(0), "curve_250")))
        probe.passes.publish(to_msg(TrainPass, train_pass_fields(_row(1, speed=float("nan")), "curve_250")))
        probe.passes.publish(to_msg(TrainPass, train_pass_fields(_row(2, vehicle_class="tram"), "curve_250")))
        assert wait_until(lambda: len(probe.noise) >= 2)
        # A state whose arrays disagree is refused; the node keeps predicting on the baseline.
        bad = _state(6.0)
        bad.amplitude_m = bad.amplitude_m[:-1]
        probe.states.publish(bad)
        assert wait_until(lambda: any(k.startswith("state refused") for k in probe.diag()))
        probe.passes.publish(to_msg(TrainPass, train_pass_fields(_row(3), "curve_250")))
        assert wait_until(lambda: len(probe.noise) >= 4)
        probe.states.publish(_state(6.0))
        assert wait_until(lambda: len(node.states) > 0)
        probe.passes.publish(to_msg(TrainPass, train_pass_fields(_row(4), "curve_250")))
        assert wait_until(lambda: len(probe.noise) >= 6)
        assert wait_until(lambda: probe.diag().get("rejected") == "2" and probe.diag().get("published") == "6")
        diag = probe.diag()
    node.destroy_node()
    probe.node.destroy_node()

    assert [m.model for m in probe.noise] == ["cnossos", "mechanics"] * 3
    assert [m.train_id for m in probe.noise] == ["T0", "T0", "T3", "T3", "T4", "T4"]
    assert diag["rejected: speed_mps not finite"] == "1"
    assert diag["rejected: vehicle_class unknown to the site"] == "1"
    first, baseline, grown = probe.noise[0], probe.noise[2], probe.noise[4]
    assert len(first.band_centre_hz) == len(first.lp_db) == len(first.lw_db) == len(first.roughness_db) == 24
    assert first.receiver_distance_m == 7.5 and first.receiver_height_m == 1.2
    assert first.roughness_growth_increase_db == 0.0 and baseline.lpaeq_tp_dba == first.lpaeq_tp_dba
    # The grown state (6 x its post-grinding roughness) raises the level by its increase since grinding.
    assert grown.roughness_growth_increase_db > 5.0
    assert grown.lpaeq_tp_dba > baseline.lpaeq_tp_dba + 5.0
    # The message carries the pure model's numbers (one conversion, no loss).
    model = RollingNoiseModel(site, noise_config(site_values))
    table = with_class_defaults(PassTable.from_rows([_row(0)]), site)
    expected = model.predict(table, "cnossos")
    assert first.lpaeq_tp_dba == expected.lpaeq_tp_dba[0]
    np.testing.assert_array_equal(first.lp_db, expected.lp_db[0])
    assert first.header.stamp == time_msg(_row(0)["stamp_ns"])
    # An EMU has no superstructure component (CNOSSOS-EU eq. 2.3.9 counts it for freight wagons only).
    assert list(first.component_names) == ["track", "vehicle"]


def test_the_deadline_timer_runs_only_while_a_pass_waits_for_its_state(ros_context, site_values):
    # Idle, the predictor has no timer to wake it: the deadline timer starts with a pass waiting for
    # its corrugation state and stops once that pass is predicted (here at its state_wait_s deadline).
    params = [Parameter(k, value=v) for k, v in site_values.items() if not k.startswith("simulator.")]
    node = RollingNoisePredictor(context=ros_context, namespace="/curve_250",
                                 parameter_overrides=[*params, Parameter("state_wait_s", value=0.3)])
    probe = Probe(ros_context)
    with spinning(ros_context, node, probe.node):
        assert wait_until(lambda: probe.passes.get_subscription_count() >= 1)
        assert node._waiting.is_canceled() and not node.pending
        probe.passes.publish(to_msg(TrainPass, train_pass_fields(_row(0), "curve_250")))
        assert wait_until(lambda: len(node.pending) == 1)  # the probe publishes states: the pass waits
        assert not node._waiting.is_canceled()
        assert wait_until(lambda: len(probe.noise) >= 2)
        assert wait_until(lambda: node._waiting.is_canceled())
        assert node.counts["predicted on the latest state (waited too long)"] == 1
    node.destroy_node()
    probe.node.destroy_node()
