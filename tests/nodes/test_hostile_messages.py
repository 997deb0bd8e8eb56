"""One of each hostile message on every topic and service of the running graph (issue 21).

The four model nodes and the recorder run in this process on one executor, spun as every
executable spins (``rail_monitor.nodes.process.spin_guarded``), on sim time, over real DDS. A
hostile node publishes, on each topic a node takes: a /clock before 1970 (rclpy's own handler
raises on it), TrainPasses with broken stamps and fields, roughness surveys that cannot apply or
lie years ahead, corrugation states, squeal predictions and rolling-noise messages no model could
have sent, and service requests with NaN and mismatched arrays. What must hold: no node stops;
each refusal is counted on /diagnostics with its reason; no alert is raised from a refused message;
the corrugation state is that of the valid passes alone; and the valid passes sent afterwards get
every output, recorded.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.serialization import serialize_message
from rosgraph_msgs.msg import Clock

from rail_monitor.bagio.reader import read_messages
from rail_monitor.core.passes import FRICTION_DRY, PassTable, with_class_defaults
from rail_monitor.corrugation.config import corrugation_config
from rail_monitor.corrugation.estimator import CorrugationEstimator
from rail_monitor.engine.site import OUT_OF_ORDER
from rail_monitor.measured.records import Measurement
from rail_monitor.messages.fields import measured_pass_noise_fields, train_pass_fields
from rail_monitor.nodes import process
from rail_monitor.nodes.alert_manager import AlertManagerNode
from rail_monitor.nodes.convert import time_msg, to_msg
from rail_monitor.nodes.corrugation_estimator import CorrugationEstimatorNode
from rail_monitor.nodes.mcap_recorder import McapRecorder
from rail_monitor.nodes.qos import CLOCK_QOS, DIAGNOSTICS_QOS, EVENT_QOS, STATE_QOS, STREAM_QOS
from rail_monitor.nodes.rolling_noise_predictor import RollingNoisePredictor
from rail_monitor.nodes.site_engine import SiteEngineNode
from rail_monitor.nodes.squeal_risk_model import SquealRiskNode
from rail_monitor.noise.config import band_centres_hz
from rail_msgs.msg import (
    CorrugationState,
    MeasuredPassNoise,
    RollingNoise,
    RoughnessSurvey,
    SquealCalibration,
    SquealPrediction,
    TrainPass,
)
from rail_msgs.srv import EvaluateSpeedDistribution

from conftest import spinning, wait_until

NS = "/curve_250"
T0 = 1_790_000_000  # [s]


def _valid_passes(site, n: int, start_s: int) -> PassTable:
    return with_class_defaults(PassTable(
        stamp_ns=(start_s + 600 * np.arange(n)) * 10**9, train_id=[f"OK-{start_s}-{k}" for k in range(n)],
        vehicle_class=["emu"] * n, vehicle_count=[4] * n, axle_count=[0] * n, speed_mps=[18.0] * n,
        angle_of_attack_rad=[0.008] * n, wheel_load_n=[0.0] * n, friction_state=[FRICTION_DRY] * n,
        train_length_m=[0.0] * n), site)


def _stamped(msg, sec: int, nanosec: int = 0):
    msg.header.stamp.sec, msg.header.stamp.nanosec = sec, nanosec
    return msg


def _hostile_passes(site) -> list[TrainPass]:
    good = train_pass_fields(_valid_passes(site, 1, T0 + 100).row(0), "curve_250")
    out = []
    for change in ({"header": {"stamp": {"sec": -5, "nanosec": 0}, "frame_id": "x"}},
                   {"header": {"stamp": {"sec": 2**31 - 1, "nanosec": 999_999_999}, "frame_id": "x"}},
                   {"speed_mps": math.nan}, {"wheel_load_n": -math.inf}, {"train_id": "\x1b[2J\x07"},
                   {"train_id": "A" * 1_000_000}, {"vehicle_class": "\u2028emu"}, {"friction_state": 255},
                   {"vehicle_count": 2**31 - 1}):
        out.append(to_msg(TrainPass, {**good, **change}))
    return out


def _hostile_surveys() -> list[RoughnessSurvey]:
    def survey(kind: int, sec: int, wl: list[float], amp: list[float]) -> RoughnessSurvey:
        return _stamped(RoughnessSurvey(kind=kind, wavelength_m=wl, amplitude_m=amp), sec)

    s = RoughnessSurvey.KIND_SURVEY
    return [survey(s, T0 + 50, [0.05, 0.1], [1e-6]), survey(s, T0 + 51, [math.nan], [1e-6]),
            survey(s, T0 + 52, [-0.05], [1e-6]), survey(s, T0 + 53, [0.05], [math.inf]),
            survey(s, -5, [0.05], [1e-6]), survey(99, T0 + 54, [0.05], [1e-6]),
            survey(s, T0 + 2 * 366 * 86_400, [0.05], [1e-6]),            # years ahead of the passes
            survey(RoughnessSurvey.KIND_GRINDING, 2**31 - 1, [], [])]


def _hostile_states() -> list[CorrugationState]:
    wl = [0.05, 0.1]

    def state(sec: int = T0 + 60, **f) -> CorrugationState:
        fields = {"wavelength_m": wl, "amplitude_m": [1e-6, 1e-6], "threshold_m": [1e-5, 1e-5],
                  "post_grinding_m": [1e-7, 1e-7], "days_to_threshold": 10.0, **f}
        return _stamped(CorrugationState(**fields), sec)

    return [state(amplitude_m=[1e-6]), state(amplitude_m=[math.nan, 1e-6]), state(wavelength_m=[], amplitude_m=[],
            threshold_m=[], post_grinding_m=[]), state(threshold_m=[0.0, 1e-5]), state(days_to_threshold=math.nan),
            state(sec=-5), state(wavelength_m=[-0.05, 0.1]), state(amplitude_m=[1.0, 1.0], grinding_due=True, sec=0)]


def _hostile_outputs() -> tuple[list[SquealPrediction], list[RollingNoise]]:
    squeal = [_stamped(SquealPrediction(train_id="S", risk=200), T0 + 70),
              _stamped(SquealPrediction(train_id="S", risk=SquealPrediction.RISK_HIGH), -5)]
    noise = [_stamped(RollingNoise(train_id="N", model="\x1b[31mred", lpafmax_dba=200.0), T0 + 70),
             _stamped(RollingNoise(train_id="N", model="cnossos", lpafmax_dba=math.nan), T0 + 70),
             _stamped(RollingNoise(train_id="N", model="cnossos", lpafmax_dba=200.0, tel_dba=math.inf), T0 + 70),
             _stamped(RollingNoise(train_id="N", model="cnossos", lpafmax_dba=200.0), 0)]
    return squeal, noise


def _hostile_fits() -> list[SquealCalibration]:
    """Squeal fits the drift alert cannot judge: arrays of different lengths, more squealing passes
    than passes, a NaN share where the window had passes, and a P10 above its P90."""
    def fit(**f) -> SquealCalibration:
        fields = {"friction_state": ["dry"], "window_passes": [100], "window_squealing": [90],
                  "window_share_p10": [0.1], "window_share_p90": [0.2], **f}
        return _stamped(SquealCalibration(**fields), T0 + 80)

    return [fit(window_passes=[100, 100]), fit(window_squealing=[101]), fit(window_share_p10=[math.nan]),
            fit(window_share_p10=[0.3])]


def _hostile_measurements(first) -> list[MeasuredPassNoise]:
    """A good measurement of the first pass (sent twice), and one of each kind the alert manager
    must refuse: a NaN band, an absurd level, a receiver 30 m away, class 9, ids without levels,
    and a pass that never was."""
    bands = band_centres_hz()
    good = Measurement(int(first.stamp_ns[0]), str(first.train_id[0]), 7.5, 1.2, 1, bands, np.full(len(bands), 70.0),
                       80.0, 83.0, 85.0)
    bad = [replace(good, leq_db=np.where(np.arange(len(bands)) == 2, np.nan, 70.0)), replace(good, tel_dba=1e6),
           replace(good, receiver_distance_m=30.0), replace(good, instrument_class=9),
           replace(good, vehicle_id=("V1", "V2")), replace(good, train_id="GHOST", stamp_ns=good.stamp_ns + 1)]
    return [to_msg(MeasuredPassNoise, measured_pass_noise_fields(m, "curve_250")) for m in (good, good, *bad)]


def _diagnostic(name: str, n_values: int) -> DiagnosticArray:
    status = DiagnosticStatus(level=DiagnosticStatus.ERROR, name=name, message="\x1b[2J" * 1000)
    status.values = [KeyValue(key=f"k{i}\x00", value="v" * 1000) for i in range(n_values)]
    return DiagnosticArray(status=[status])


@pytest.fixture()
def graph(ros_context, site_values, tmp_path):
    params = [Parameter(k, value=v) for k, v in site_values.items() if not k.startswith("simulator.")]
    params.append(Parameter("use_sim_time", value=True))
    kw = {"context": ros_context, "namespace": NS, "parameter_overrides": params}
    models = [CorrugationEstimatorNode(**kw), RollingNoisePredictor(context=ros_context, namespace=NS,
              parameter_overrides=[*params, Parameter("state_wait_s", value=0.5)]), SquealRiskNode(**kw),
              AlertManagerNode(**kw)]
    recorder = McapRecorder(context=ros_context, parameter_overrides=[Parameter("output", value=str(tmp_path / "bag"))])
    hostile = Node("hostile", context=ros_context, namespace=NS)
    process.CALLBACK_ERRORS.clear()
    with spinning(ros_context, *models, recorder, hostile):
        yield models, recorder, hostile
    recorder.close()
    for n in [*models, recorder, hostile]:
        n.destroy_node()


def test_one_of_each_hostile_message_stops_no_node_and_each_is_counted(graph, site, site_values, tally):
    (est, noise, squeal, alerts), recorder, hostile = graph
    pubs = {t: hostile.create_publisher(m, t, q) for t, m, q in (
        ("/clock", Clock, CLOCK_QOS), ("train_pass", TrainPass, STREAM_QOS),
        ("roughness_survey", RoughnessSurvey, EVENT_QOS), ("corrugation/state", CorrugationState, STATE_QOS),
        ("noise/squeal", SquealPrediction, STREAM_QOS), ("noise/rolling", RollingNoise, STREAM_QOS),
        ("noise/measured", MeasuredPassNoise, STREAM_QOS), ("/diagnostics", DiagnosticArray, DIAGNOSTICS_QOS),
        ("noise/squeal_calibration", SquealCalibration, STREAM_QOS))}
    client = hostile.create_client(EvaluateSpeedDistribution, "evaluate_speed_distribution")
    assert wait_until(lambda: pubs["train_pass"].get_subscription_count() >= 5 and client.service_is_ready()
                      and all(p.get_subscription_count() >= 1 for p in pubs.values()), 20)
    first = _valid_passes(site, 3, T0)
    for i in range(3):
        pubs["train_pass"].publish(to_msg(TrainPass, train_pass_fields(first.row(i), "curve_250")))
    assert wait_until(lambda: est.counts["counted"] == 3 and alerts.inputs["noise/rolling"] >= 6, 10)

    bad_clock = Clock()
    bad_clock.clock.sec = -5
    pubs["/clock"].publish(bad_clock)
    bad_passes, surveys, states = _hostile_passes(site), _hostile_surveys(), _hostile_states()
    squeals, noises = _hostile_outputs()
    # and two states that are not CDR of a state at all (raw bytes): one cut short, one noise
    whole = bytes(serialize_message(states[0]))
    states_raw = [whole[: len(whole) // 2], bytes(np.random.default_rng(3).integers(0, 256, 300, np.uint8))]
    whole = bytes(serialize_message(bad_passes[0]))
    passes_raw = [whole[:20], b"\x00\x01\x00\x00" + bytes(np.random.default_rng(4).integers(0, 256, 90, np.uint8))]
    for topic, msgs in (("train_pass", bad_passes), ("train_pass", passes_raw), ("roughness_survey", surveys),
                        ("corrugation/state", states),
                        ("corrugation/state", states_raw),
                        ("noise/squeal", squeals), ("noise/rolling", noises),
                        ("noise/measured", _hostile_measurements(first)),
                        ("noise/squeal_calibration", fits := _hostile_fits()),
                        ("/diagnostics", [_diagnostic("fake", 2000)])):
        for m in msgs:
            pubs[topic].publish(m)
    requests = [EvaluateSpeedDistribution.Request(speed_mps=[math.nan], probability=[1.0]),
                EvaluateSpeedDistribution.Request(speed_mps=[15.0, 20.0], probability=[1.0]),
                EvaluateSpeedDistribution.Request(speed_mps=[], probability=[]),
                EvaluateSpeedDistribution.Request(speed_mps=[15.0], probability=[-1.0]),
                EvaluateSpeedDistribution.Request(speed_mps=[15.0], probability=[1.0], friction_state=200),
                EvaluateSpeedDistribution.Request(speed_mps=[15.0], probability=[1.0], passes_per_day=math.inf)]
    futures = [client.call_async(r) for r in requests]
    assert wait_until(lambda: all(f.done() for f in futures), 20)
    assert not any(f.result().success for f in futures), [f.result().message for f in futures]

    n_bad = len(bad_passes) + len(passes_raw)
    assert wait_until(lambda: all(n.taken == 3 + n_bad for n in (est, noise, squeal, alerts)), 20)
    assert wait_until(lambda: sum(est.surveys_rejected.values()) == len(surveys)
                      and sum(noise.states_rejected.values()) == 4 + 2  # the arrays it reads: 4 of the 8
                      and alerts.inputs["corrugation/state"] >= 3 + len(states) + 2
                      and alerts.inputs["noise/rolling"] >= 6 + len(noises), 20), \
        (est.surveys_rejected, noise.states_rejected, alerts.inputs)
    for node in (est, noise, squeal, alerts):
        assert sum(node.rejected.values()) == n_bad, (node.get_name(), node.rejected)
        assert node.rejected["not a readable TrainPass (CDR)"] == len(passes_raw), node.rejected
        assert not node.model_errors
    refused = {k: n for k, n in alerts.inputs.items() if " refused: " in k}
    assert sum(n for k, n in refused.items() if k.startswith("corrugation/state")) == len(states) + 2, refused
    assert sum(n for k, n in refused.items() if "not a readable CDR message" in k) == 2, refused
    assert sum(n for k, n in refused.items() if k.startswith("noise/squeal refused")) == len(squeals), refused
    assert sum(n for k, n in refused.items() if k.startswith("noise/rolling")) == len(noises), refused
    assert wait_until(lambda: sum(n for k, n in alerts.inputs.items()
                                  if k.startswith("noise/squeal_calibration refused")) == len(fits), 10), alerts.inputs
    assert est.surveys_rejected["stamp more than 366 d ahead of the stream (stamps.max_ahead_of_stream_s)"] == 2, \
        est.surveys_rejected
    assert any(why.startswith("ValueError") for why in process.CALLBACK_ERRORS), process.CALLBACK_ERRORS
    assert not any("red" in a.key or a.key == "N" for a in alerts.recent)

    # Every node goes on: valid passes after the storm get every output, recorded.
    after = _valid_passes(site, 4, T0 + 7200)
    for i in range(4):
        pubs["train_pass"].publish(to_msg(TrainPass, train_pass_fields(after.row(i), "curve_250")))
    pubs["/clock"].publish(Clock(clock=time_msg((T0 + 9000) * 10**9)))
    assert wait_until(lambda: est.counts["counted"] == 7 and squeal.sent[f"{NS}/noise/squeal"] == 7
                      and noise.sent[f"{NS}/noise/rolling"] == 14, 30), (est.counts, squeal.sent, noise.sent)
    pure = CorrugationEstimator(site, corrugation_config(site_values))
    pure.advance(PassTable.concat([first, after]))
    np.testing.assert_array_equal(est.est.log_components, pure.log_components)
    # the measurements: the good one paired once (a residual per model), each bad one refused by reason
    want = {"pass measured twice", "a band level or single number is not finite", "a level is outside 0-150 dB",
            "receiver (30 m, 1.2 m) is not the model's (7.5 m, 1.2 m)", "instrument class 9 is not 1 or 2",
            "vehicle_id and vehicle_lpaeq_dba differ in length, or a vehicle level is not a level",
            "no prediction for this pass (no such pass, or it was rejected)"}
    assert wait_until(lambda: set(alerts.tracker.refused) == want, 20), alerts.tracker.refused
    assert sum(alerts.tracker.refused.values()) == 7 and alerts.sent[f"{NS}/noise/residual"] == 2
    assert wait_until(lambda: recorder.counts.get(f"{NS}/noise/rolling", 0) >= 14, 20)
    recorder.close()
    recorded = read_messages(recorder.writer.folder, ["rail_msgs/msg/SquealPrediction", "rail_msgs/msg/RollingNoise"])
    ids = [m.train_id for m in recorded["rail_msgs/msg/SquealPrediction"]]  # the hostile ones are recorded too
    assert [i for i in ids if i.startswith("OK-")] == [*first.train_id.tolist(), *after.train_id.tolist()]
    tally("hostile messages", f"{n_bad} TrainPass, {len(surveys)} surveys, {len(states)} states, {len(squeals)} squeal "
          f"and {len(noises)} noise messages, 7 bad measured pass-bys, a /clock before 1970, a 2000-entry "
          f"diagnostic and {len(requests)} service requests into the running graph",
          "no node stopped; each refused and counted by reason; no alert from them; state of the valid passes; "
          "the 4 valid passes after them fully predicted and recorded", 0)


def test_the_site_engine_node_takes_the_same_storm(ros_context, site, site_values, tmp_path):
    """site_engine (the one-process graph's models) under the same hostile passes, surveys,
    measurements and service requests, and a pass older than one already taken: it stops not,
    counts each refusal by reason, and its state is that of the valid passes alone; the valid
    passes after the storm get every output."""
    params = [Parameter(k, value=v) for k, v in site_values.items() if not k.startswith("simulator.")]
    params.append(Parameter("use_sim_time", value=True))
    node = SiteEngineNode(context=ros_context, namespace=NS, parameter_overrides=params)
    hostile = Node("hostile", context=ros_context, namespace=NS)
    got: dict[str, list] = {"squeal": [], "rolling": []}
    hostile.create_subscription(SquealPrediction, "noise/squeal", got["squeal"].append, STREAM_QOS)
    hostile.create_subscription(RollingNoise, "noise/rolling", got["rolling"].append, STREAM_QOS)
    pubs = {t: hostile.create_publisher(m, t, q) for t, m, q in (
        ("/clock", Clock, CLOCK_QOS), ("train_pass", TrainPass, STREAM_QOS),
        ("roughness_survey", RoughnessSurvey, EVENT_QOS), ("noise/measured", MeasuredPassNoise, STREAM_QOS))}
    client = hostile.create_client(EvaluateSpeedDistribution, "evaluate_speed_distribution")
    process.CALLBACK_ERRORS.clear()
    try:
        with spinning(ros_context, node, hostile):
            assert wait_until(lambda: client.service_is_ready()
                              and all(p.get_subscription_count() >= 1 for t, p in pubs.items() if t != "/clock"), 20)
            first = _valid_passes(site, 3, T0)
            for i in range(3):
                pubs["train_pass"].publish(to_msg(TrainPass, train_pass_fields(first.row(i), "curve_250")))
            assert wait_until(lambda: node.counts["counted"] == 3, 10)
            older = first.take(np.array([0]))  # a copy
            older.stamp_ns[0] -= 10**9  # before a pass already taken
            bad_passes = [*_hostile_passes(site), to_msg(TrainPass, train_pass_fields(older.row(0), "curve_250"))]
            for topic, msgs in (("train_pass", bad_passes), ("roughness_survey", _hostile_surveys()),
                                ("noise/measured", _hostile_measurements(first))):
                for m in msgs:
                    pubs[topic].publish(m)
            futures = [client.call_async(EvaluateSpeedDistribution.Request(speed_mps=s, probability=p))
                       for s, p in (([math.nan], [1.0]), ([15.0, 20.0], [1.0]), ([], []), ([15.0], [-1.0]))]
            assert wait_until(lambda: all(f.done() for f in futures), 20)
            assert not any(f.result().success for f in futures)
            assert wait_until(lambda: node.taken == 3 + len(bad_passes)
                              and sum(node.engine.corrugation.refused.values()) == len(_hostile_surveys()), 20), \
                (node.taken, node.engine.corrugation.refused)
            assert sum(node.rejected.values()) == len(bad_passes) and not node.model_errors, node.rejected
            assert node.rejected[OUT_OF_ORDER] == 1, node.rejected
            after = _valid_passes(site, 4, T0 + 7200)
            for i in range(4):
                pubs["train_pass"].publish(to_msg(TrainPass, train_pass_fields(after.row(i), "curve_250")))
            assert wait_until(lambda: node.counts["counted"] == 7 and len(got["squeal"]) == 7
                              and len(got["rolling"]) == 14, 30), (node.counts, len(got["squeal"]))
            assert wait_until(lambda: sum(node.engine.tracker.refused.values()) == 7, 20), node.engine.tracker.refused
    finally:
        node.close()
        for n in (node, hostile):
            n.destroy_node()
    pure = CorrugationEstimator(site, corrugation_config(site_values))
    pure.advance(PassTable.concat([first, after]))
    np.testing.assert_array_equal(node.engine.estimator.log_components, pure.log_components)
    assert [m.train_id for m in got["squeal"]] == [*first.train_id.tolist(), *after.train_id.tolist()]
    assert not process.CALLBACK_ERRORS, process.CALLBACK_ERRORS
