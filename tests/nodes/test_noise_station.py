"""noise_station in-process over real DDS: each pass heard from its recorded audio and published as
a MeasuredPassNoise with its squeal; a pass without audio and one with a damaged file counted,
not lost; the passes worth hearing archived, a wheel-defect suspect among them (issue 54)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from diagnostic_msgs.msg import DiagnosticArray
from rclpy.node import Node

from rail_monitor.core.passes import FRICTION_BY_NAME, PassTable, with_class_defaults
from rail_monitor.messages.fields import measurement_from_msg, train_pass_fields
from rail_monitor.nodes.convert import to_msg
from rail_monitor.nodes.noise_station import NoiseStation
from rail_monitor.nodes.qos import STREAM_QOS, STREAM_SUB_QOS
from rail_monitor.station.archive import INDEX, LOUDEST, SQUEAL, SUSPECT
from rail_monitor.station.config import station_config
from rail_monitor.station.pass_audio import audio_name, hear_pass, measurement
from rail_msgs.msg import MeasuredPassNoise, NoiseResidual, TrainPass

from conftest import node_parameters, same_record, spinning, wait_until, write_pass_audio

T0 = 1_790_000_000 * 10**9
# (train id, friction, angle of attack [mrad], audio): a dry pass, a wet squealing one, another
# dry one, one whose recorder left nothing and one whose file is damaged.
PASSES = [("D1", "dry", 0.0, "wav"), ("W2", "wet", 10.0, "wav"), ("D3", "dry", 0.0, "wav"),
          ("N4", "dry", 0.0, None), ("B5", "dry", 0.0, "bad")]


def test_each_pass_is_heard_from_its_audio_and_the_worth_hearing_kept(ros_context, site, site_values, tmp_path):
    audio, archive = tmp_path / "recorder", tmp_path / "archive"
    audio.mkdir()
    cls = site.vehicle("emu")
    stamps = []
    for i, (train, friction, aoa, kind) in enumerate(PASSES):
        stamps.append(T0 + i * 600 * 10**9)
        if kind == "wav":
            a = write_pass_audio(audio, stamps[-1], train, lead_s=1.0, vehicle_class="emu", friction=friction,
                                 aoa_mrad=aoa, seed=i)
        elif kind == "bad":
            (audio / audio_name(stamps[-1], train)).write_bytes(b"RIFF\x10\x00\x00\x00WAVEjunk")
    tp = a.pass_time_s  # every pass the same train at the same speed
    table = with_class_defaults(PassTable(
        stamp_ns=stamps, train_id=[p[0] for p in PASSES], vehicle_class=["emu"] * 5,
        vehicle_count=[round(cls.mean_vehicles)] * 5, axle_count=[0] * 5, speed_mps=[cls.speed_mean_mps] * 5,
        angle_of_attack_rad=[1e-3 * p[2] for p in PASSES],
        wheel_load_n=[0.0] * 5, friction_state=[FRICTION_BY_NAME[p[1]] for p in PASSES],
        train_length_m=[tp * cls.speed_mean_mps] * 5), site)
    station = {"station.audio_folder": str(audio), "station.lead_s": 1.0, "station.sensitivity_pa_per_unit": 1.0,
               "station.audio_wait_s": 3.0, "station.archive_folder": str(archive), "station.loudest_per_day": 1}
    node = NoiseStation(context=ros_context, namespace="/curve_250",
                        parameter_overrides=node_parameters(site_values, **station))
    probe = Node("probe", context=ros_context, namespace="/curve_250")
    passes = probe.create_publisher(TrainPass, "train_pass", STREAM_QOS)
    residuals = probe.create_publisher(NoiseResidual, "noise/residual", STREAM_QOS)
    got: list[MeasuredPassNoise] = []
    diags: list[DiagnosticArray] = []
    probe.create_subscription(MeasuredPassNoise, "noise/measured", got.append, STREAM_SUB_QOS)
    probe.create_subscription(DiagnosticArray, "/diagnostics", diags.append, 10)

    def diag() -> dict[str, str]:
        for d in reversed(diags):
            for s in d.status:
                if s.name.endswith("noise_station"):
                    return {kv.key: kv.value for kv in s.values}
        return {}

    with spinning(ros_context, node, probe):
        assert wait_until(lambda: passes.get_subscription_count() >= 1 and residuals.get_subscription_count() >= 1)
        for i in range(len(table)):
            passes.publish(to_msg(TrainPass, train_pass_fields(table.row(i), "curve_250")))
        assert wait_until(lambda: diag().get("pending") == "0" and diag().get("taken") == "5", timeout_s=30)
        assert wait_until(lambda: len(got) == 3)
        values = diag()
        assert (values["heard"], values["squealing"]) == ("3", "1")
        assert values["not heard: no audio within audio_wait_s"] == "1"
        assert values["not heard: audio unusable"] == "1"
        # The graph's message is the station's measurement of that file, every field.
        cfg = station_config(station)
        for msg in got:
            m = measurement_from_msg(msg)
            want = measurement(m.stamp_ns, m.train_id, hear_pass(audio / audio_name(*m.key), 1.0, cfg, tp), cfg)
            assert same_record(m, want)
        heard = {m.train_id: m for m in map(measurement_from_msg, got)}
        assert [heard[t].squeal_detected for t in ("D1", "W2", "D3")] == [False, True, False]
        assert heard["D1"].lpaeq_tp_dba == pytest.approx(a.lpaeq_tp_dba, abs=0.5)  # another seed: 0.5 dB
        # Archived: the squealing pass (the day's loudest too); then D3 named a wheel-defect suspect.
        index = {row["train_id"]: row["reasons"] for row in json.loads((archive / INDEX).read_text())}
        assert index == {"W2": [SQUEAL, LOUDEST]}
        residuals.publish(to_msg(NoiseResidual, {"header": {"stamp": {"sec": stamps[2] // 10**9, "nanosec": 0},
                                                            "frame_id": "curve_250"},
                                                 "train_id": "D3", "model": "cnossos", "excess_mid_db": 7.5}))
        assert wait_until(lambda: (archive / audio_name(stamps[2], "D3")).is_file())
        index = {row["train_id"]: row["reasons"] for row in json.loads((archive / INDEX).read_text())}
        assert index == {"W2": [SQUEAL, LOUDEST], "D3": [SUSPECT]}
        assert sorted(p.name for p in audio.iterdir()) == sorted(
            audio_name(s, p[0]) for s, p in zip(stamps, PASSES, strict=True) if p[3])  # the recorder's untouched
        assert np.isfinite(heard["W2"].squeal_frequency_hz)
    node.destroy_node()
    probe.destroy_node()
