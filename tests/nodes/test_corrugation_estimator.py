"""corrugation_estimator in-process over real DDS: state per pass, rejections, identity, surveys,
the what-if service, the advisory, and a restart from its checkpoint."""

from __future__ import annotations

import numpy as np
import pytest
from diagnostic_msgs.msg import DiagnosticArray
from rclpy.node import Node
from rclpy.parameter import Parameter

from rail_monitor.advice import growth as advice
from rail_monitor.advice import plan
from rail_monitor.advice.consequences import Consequences
from rail_monitor.core.passes import FRICTION_DRY, PassTable, with_class_defaults
from rail_monitor.corrugation import surveys
from rail_monitor.corrugation.config import corrugation_config
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.messages.fields import train_pass_fields
from rail_monitor.nodes.convert import time_msg, to_msg
from rail_monitor.nodes.corrugation_estimator import CorrugationEstimatorNode
from rail_monitor.nodes.qos import EVENT_QOS, LATEST_QOS, STREAM_QOS
from rail_monitor.nodes.site_engine import SiteEngineNode
from rail_monitor.noise.config import noise_config
from rail_monitor.noise.predict import RollingNoiseModel
from rail_monitor.squeal.config import squeal_config
from rail_msgs.msg import CorrugationState, RoughnessSurvey, SpeedAdvisory, TrainPass
from rail_msgs.srv import EvaluateSpeedDistribution

from conftest import spinning, wait_until


def _passes(site, n: int, start: int = 0) -> PassTable:
    i = np.arange(start, start + n)
    return with_class_defaults(PassTable(
        stamp_ns=(1_790_000_000 + i * 600) * 10**9, train_id=[f"T{k}" for k in i], vehicle_class=["emu"] * n,
        vehicle_count=[4] * n, axle_count=[0] * n, speed_mps=15.0 + 6.0 * (i % 7) / 6.0,
        angle_of_attack_rad=[0.0] * n, wheel_load_n=[0.0] * n, friction_state=[FRICTION_DRY] * n,
        train_length_m=[0.0] * n), site)


def _node(ctx, site_values, cls=CorrugationEstimatorNode, **extra) -> CorrugationEstimatorNode:
    params = [Parameter(k, value=v) for k, v in {**site_values, **extra}.items() if not k.startswith("simulator.")]
    return cls(context=ctx, namespace="/curve_250", parameter_overrides=params)


class Probe:
    def __init__(self, ctx) -> None:
        self.node = Node("probe", context=ctx, namespace="/curve_250")
        self.states: list[CorrugationState] = []
        self.advisories: list[SpeedAdvisory] = []
        self.diags: list[DiagnosticArray] = []
        self.node.create_subscription(CorrugationState, "corrugation/state", self.states.append, LATEST_QOS)
        self.node.create_subscription(SpeedAdvisory, "speed_advisory", self.advisories.append, LATEST_QOS)
        self.node.create_subscription(DiagnosticArray, "/diagnostics", self.diags.append, 10)
        self.passes = self.node.create_publisher(TrainPass, "train_pass", STREAM_QOS)
        self.surveys = self.node.create_publisher(RoughnessSurvey, "roughness_survey", EVENT_QOS)
        self.client = self.node.create_client(EvaluateSpeedDistribution, "evaluate_speed_distribution")

    def send(self, table: PassTable) -> None:
        for i in range(len(table)):
            self.passes.publish(to_msg(TrainPass, train_pass_fields(table.row(i), "curve_250")))

    def diag(self) -> dict[str, str]:
        for d in reversed(self.diags):
            for s in d.status:
                if s.name.endswith("corrugation_estimator"):
                    return {kv.key: kv.value for kv in s.values}
        return {}

    def evaluate(self, speeds, probability) -> EvaluateSpeedDistribution.Response:
        fut = self.client.call_async(EvaluateSpeedDistribution.Request(speed_mps=speeds, probability=probability))
        assert wait_until(fut.done)
        return fut.result()


def test_node_state_rejections_identity_surveys_service_and_advisory(ros_context, site, site_values):
    node = _node(ros_context, site_values, advisory_period_s=0.2)
    probe = Probe(ros_context)
    good = _passes(site, 30)
    with spinning(ros_context, node, probe.node):
        assert wait_until(lambda: probe.passes.get_subscription_count() >= 1 and probe.client.service_is_ready())
        probe.send(good.take(slice(0, 20)))
        bad = dict(good.row(0), speed_mps=-3.0, train_id="negative-speed")
        probe.passes.publish(to_msg(TrainPass, train_pass_fields(bad, "curve_250")))
        probe.send(good)                                  # the first 20 again, then 10 new ones
        # The state topic is latched with depth 1: a subscriber sees the latest, not every one.
        assert wait_until(lambda: probe.states and probe.states[-1].total_pass_count == 30
                          and probe.diag().get("rejected") == "1" and probe.diag().get("counted") == "30")
        last = probe.states[-1]
        pure = CorrugationEstimator(site, corrugation_config(site_values))
        pure.advance(good)
        np.testing.assert_allclose(last.amplitude_m, pure.amplitude, rtol=1e-12)
        assert last.total_pass_count == 30 and last.header.frame_id == "curve_250"
        assert last.days_to_threshold == pytest.approx(pure.forecast().days_to_threshold, rel=1e-12)
        values = probe.diag()
        assert values["rejected: speed_mps not positive"] == "1"
        assert values["not counted (already counted, or older than the history)"] == "20"

        res = probe.evaluate([14.0, 18.0, 22.0], [1.0, 2.0, 1.0])
        assert res.success and len(res.growth_per_axle_pass) == len(pure.bands)
        want = advice.evaluate(pure, np.array([14.0, 18.0, 22.0]), np.array([1.0, 2.0, 1.0]))
        assert res.peak_growth == pytest.approx(want.peak_growth, rel=1e-12)
        # ... with what the distribution does to noise and squeal against the recent passes
        cons = Consequences(site, RollingNoiseModel(site, noise_config(site_values)), squeal_config(site_values))
        side = plan.evaluate_consequences(pure, cons, np.array([14.0, 18.0, 22.0]), np.array([1.0, 2.0, 1.0]))
        assert list(res.noise_model) == side.noise_model
        np.testing.assert_allclose(res.noise_change_dba, side.noise_change_dba, rtol=1e-12)
        assert (res.squeal_share_current, res.squeal_share) == (side.squeal_share_current, side.squeal_share)
        refused = probe.evaluate([14.0, -1.0], [1.0, 1.0])
        assert not refused.success and "speeds" in refused.message

        assert wait_until(lambda: len(probe.advisories) >= 1)
        adv = probe.advisories[-1]
        assert sum(adv.recommended_probability) == pytest.approx(1.0)
        assert adv.grinding_interval_factor >= 1.0 and adv.peak_growth_reduction >= 0.0
        want_adv = plan.advise(pure, cons)
        assert list(adv.vehicle_class) == want_adv.vehicle_class == ["emu"]
        np.testing.assert_allclose(adv.band_recommended_share, want_adv.band_recommended_share, atol=1e-9)
        assert list(adv.noise_model) == want_adv.noise_model
        assert adv.squeal_share_recommended <= adv.squeal_share_current + 1e-9

        # A grinding stamped after every pass waits for the first pass later than it (as batch mode
        # applies it), then resets the state before that pass counts.
        grind = RoughnessSurvey(kind=RoughnessSurvey.KIND_GRINDING)
        grind.header.stamp = time_msg(int(good.stamp_ns[-1]) + 10**9)
        probe.surveys.publish(grind)
        assert wait_until(lambda: probe.diag().get("surveys pending") == "1")
        assert probe.states[-1].total_pass_count == 30
        after = _passes(site, 1, start=30)
        probe.send(after)
        assert wait_until(lambda: probe.states[-1].total_pass_count == 31)
        surveys.apply_grinding(pure, int(good.stamp_ns[-1]) + 10**9)
        pure.advance(after)
        assert probe.states[-1].pass_count == 1
        assert wait_until(lambda: probe.diag().get("grindings") == "1")
        np.testing.assert_allclose(probe.states[-1].amplitude_m, pure.amplitude, rtol=1e-12)
        stale = RoughnessSurvey(kind=RoughnessSurvey.KIND_SURVEY, wavelength_m=[0.1], amplitude_m=[1e-6])
        stale.header.stamp = time_msg(int(good.stamp_ns[0]))
        probe.surveys.publish(stale)
        assert wait_until(lambda: any(k.startswith("survey rejected: not newer") for k in probe.diag()))
        # A survey stamped between counted passes can only be applied on arrival: counted as late,
        # and the state it gives is published at once.
        late = RoughnessSurvey(kind=RoughnessSurvey.KIND_SURVEY, wavelength_m=pure.bands.tolist(),
                               amplitude_m=(2 * pure.post_grinding).tolist())
        late.header.stamp = time_msg(int(after.stamp_ns[0]) - 10**9)
        probe.surveys.publish(late)
        assert wait_until(lambda: probe.diag().get("surveys") == "1"
                          and probe.diag().get("applied late (passes after its stamp already counted)") == "1")
        surveys.apply_survey(pure, pure.bands, 2 * pure.post_grinding, int(after.stamp_ns[0]) - 10**9)
        assert wait_until(lambda: np.allclose(probe.states[-1].amplitude_m, pure.amplitude, rtol=1e-12, atol=0))


@pytest.mark.parametrize("cls", [CorrugationEstimatorNode, SiteEngineNode], ids=["estimator", "engine"])
def test_state_period_sends_the_whole_state_at_most_that_often(ros_context, site, site_values, cls):
    """state_period_s > 0 (docs/parameters.md): the state is not sent per pass but, at most every
    state_period_s of wall time, the whole state then (the same helper in both nodes); a survey
    applied on arrival sends it at once. The state sent must equal an estimator advanced by the
    passes counted when it was sent."""
    node = _node(ros_context, site_values, cls=cls, state_period_s=3600.0)
    probe = Probe(ros_context)
    good = _passes(site, 30)
    topic = "/curve_250/corrugation/state"
    with spinning(ros_context, node, probe.node):
        assert wait_until(lambda: probe.passes.get_subscription_count() >= 1)
        probe.send(good)
        assert wait_until(lambda: node.taken == 30 and len(probe.states) == 1)
        assert node.sent[topic] == 1, "one state within the period, not one per pass"
        first = probe.states[0]
        pure = CorrugationEstimator(site, corrugation_config(site_values))
        pure.advance(good.take(slice(0, first.total_pass_count)))
        np.testing.assert_allclose(first.amplitude_m, pure.amplitude, rtol=1e-12)
        # A survey stamped among the counted passes is applied on arrival: the state goes out now.
        pure = CorrugationEstimator(site, corrugation_config(site_values))
        pure.advance(good)
        late = RoughnessSurvey(kind=RoughnessSurvey.KIND_SURVEY, wavelength_m=pure.bands.tolist(),
                               amplitude_m=(2 * pure.post_grinding).tolist())
        late.header.stamp = time_msg(int(good.stamp_ns[-1]) - 10**9)
        probe.surveys.publish(late)
        assert wait_until(lambda: node.sent[topic] == 2 and len(probe.states) == 2)
        assert probe.states[-1].total_pass_count == 30


def test_restart_resumes_from_the_checkpoint(ros_context, site, site_values, tmp_path):
    ckpt = str(tmp_path / "corrugation.npz")
    passes = _passes(site, 40)
    first = _node(ros_context, site_values, checkpoint_path=ckpt, checkpoint_every_passes=1000)
    probe = Probe(ros_context)
    with spinning(ros_context, first, probe.node):
        assert wait_until(lambda: probe.passes.get_subscription_count() >= 1)
        probe.send(passes.take(slice(0, 25)))
        assert wait_until(lambda: first.counts["counted"] == 25)
    first.close()                                         # what run_node does at shutdown
    first.destroy_node()

    second = _node(ros_context, site_values, checkpoint_path=ckpt)
    assert second.est.total_pass_count == 25
    probe.states.clear()
    with spinning(ros_context, second, probe.node):
        assert wait_until(lambda: probe.passes.get_subscription_count() >= 1)
        probe.send(passes)                                # a replay of everything: 15 are new
        assert wait_until(lambda: second.counts["counted"] == 15 and probe.states
                          and probe.states[-1].total_pass_count == 40)
    pure = CorrugationEstimator(site, corrugation_config(site_values))
    pure.advance(passes)
    np.testing.assert_allclose(probe.states[-1].amplitude_m, pure.amplitude, rtol=1e-12)
    assert probe.states[-1].total_pass_count == 40


def test_the_site_file_configures_the_node_through_its_own_section(ros_context, tmp_path):
    # The shipped file's '/**/corrugation_estimator' section reaches this node (rcl's wildcard match).
    from conftest import SITE_FILE

    text = SITE_FILE.read_text().replace("advisory_period_s: 60.0", "advisory_period_s: 7.5")
    text = text.replace("lead_time_days: 60.0", "lead_time_days: 30.0")
    f = tmp_path / "site.yaml"
    f.write_text(text)
    node = CorrugationEstimatorNode(context=ros_context, namespace="/curve_250",
                                    cli_args=["--ros-args", "--params-file", str(f)])
    assert node.params.advisory_period_s == 7.5 and node.est.cfg.lead_time_days == 30.0
    assert node.site.site_id == "curve_250"
    node.destroy_node()
