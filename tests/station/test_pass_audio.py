"""A pass's recorded audio heard as a station hears it (rail_monitor.station.pass_audio), and the
squeal measures a measured pass-by carries (MeasuredPassNoise, the station CSV, their checks)."""

from __future__ import annotations

from datetime import UTC, datetime

import numpy as np
import pytest

from rail_monitor.bagio.measured_csv import read_measured_csv, write_measured_csv
from rail_monitor.measured.records import measurement_refusal
from rail_monitor.messages.fields import measured_pass_noise_fields, measurement_from_msg
from rail_monitor.nodes.convert import to_msg
from rail_monitor.station.config import station_config
from rail_monitor.station.pass_audio import audio_name, hear_pass, measurement
from rail_msgs.msg import MeasuredPassNoise

from conftest import same_record, write_pass_audio

STAMP = 1_790_000_000_123_456_789
MODEL_BANDS = 1000.0 * 10.0 ** (np.arange(-13, 11) / 10.0)


def test_the_file_name_holds_the_stamp_to_the_nanosecond_and_a_safe_train_id():
    name = audio_name(STAMP, "IC 2/3:x")
    stamp, rest = name.split("Z_")
    when = datetime.strptime(stamp[:15], "%Y%m%dT%H%M%S").replace(tzinfo=UTC)
    assert int(when.timestamp()) * 10**9 + int(stamp[16:]) == STAMP
    assert rest == "IC_2_3_x.wav"


@pytest.mark.parametrize(("friction", "aoa_mrad", "squeals"), [("dry", 0.0, False), ("wet", 10.0, True)])
def test_a_recorded_pass_is_heard_with_its_predicted_levels_and_squeal(tmp_path, friction, aoa_mrad, squeals):
    """The predicted pass written as the recorder leaves it: heard from lead_s over Tp (the train's
    length over its speed), LpAeq,Tp and TEL within 0.15 dB of the prediction (the tolerance of
    tests/whatif/test_audio.py), and the squeal at its predicted frequency within 1 % (the Doppler
    shift of the pass's middle) when the model finds the pass unstable."""
    a = write_pass_audio(tmp_path, STAMP, "T1", lead_s=1.0, friction=friction, aoa_mrad=aoa_mrad, seed=3)
    cfg = station_config({"station.audio_folder": str(tmp_path), "station.lead_s": 1.0,
                          "station.sensitivity_pa_per_unit": 1.0})
    heard = hear_pass(tmp_path / audio_name(STAMP, "T1"), 1.0, cfg, a.pass_time_s)
    m = measurement(STAMP, "T1", heard, cfg)
    assert m.lpaeq_tp_dba == pytest.approx(a.lpaeq_tp_dba if not squeals else heard.levels.lpaeq_tp_db, abs=0.15)
    if not squeals:
        assert m.tel_dba == pytest.approx(a.tel_dba, abs=0.15)
        assert not m.squeal_detected and np.isnan(m.squeal_frequency_hz) and m.squeal_duration_s == 0.0
    else:
        assert m.squeal_detected and m.squeal_frequency_hz == pytest.approx(a.squeal_hz, rel=0.01)
        assert m.squeal_duration_s > 0.8 * a.pass_time_s and np.isfinite(m.squeal_level_db)
        assert m.lpaeq_tp_dba > a.lpaeq_tp_dba + 3.0  # the tone dominates the rolling noise
    assert (m.receiver_distance_m, m.receiver_height_m, m.instrument_class) == (7.5, 1.2, 1)
    assert measurement_refusal(m, MODEL_BANDS, (7.5, 1.2), 0.5) == ""


def test_the_squeal_measures_survive_the_message_and_the_station_csv(tmp_path):
    write_pass_audio(tmp_path, STAMP, "T1", friction="wet", aoa_mrad=10.0, seed=3)
    a = write_pass_audio(tmp_path, STAMP + 1, "T2", seed=4)
    cfg = station_config({"station.audio_folder": str(tmp_path), "station.lead_s": 1.0,
                          "station.sensitivity_pa_per_unit": 1.0})
    ms = [measurement(s, t, hear_pass(tmp_path / audio_name(s, t), 1.0, cfg, a.pass_time_s), cfg)
          for s, t in ((STAMP, "T1"), (STAMP + 1, "T2"))]
    assert [m.squeal_detected for m in ms] == [True, False]
    for m in ms:
        assert same_record(measurement_from_msg(to_msg(MeasuredPassNoise, measured_pass_noise_fields(m, "s"))), m)
    write_measured_csv(ms, tmp_path / "station.csv")
    back = read_measured_csv(tmp_path / "station.csv")
    assert all(same_record(x, y) for x, y in zip(back, ms, strict=True))


def test_squeal_measures_out_of_range_or_on_a_quiet_pass_are_refused():
    base = dict(stamp_ns=STAMP, train_id="T", receiver_distance_m=7.5, receiver_height_m=1.2, instrument_class=1,
                band_centre_hz=MODEL_BANDS[:3], leq_db=np.full(3, 70.0), lpaeq_tp_dba=80.0, lpafmax_dba=82.0,
                tel_dba=79.0)
    from rail_monitor.measured.records import Measurement

    assert measurement_refusal(Measurement(**base, squeal_detected=True), MODEL_BANDS, (7.5, 1.2), 0.5) == ""
    for bad in ({"squeal_frequency_hz": -5.0}, {"squeal_level_db": 400.0}, {"squeal_duration_s": -1.0},
                {"squeal_frequency_hz": float("inf")}):
        why = measurement_refusal(Measurement(**base, squeal_detected=True, **bad), MODEL_BANDS, (7.5, 1.2), 0.5)
        assert why.startswith("a squeal measure is out of range")
    why = measurement_refusal(Measurement(**base, squeal_frequency_hz=800.0), MODEL_BANDS, (7.5, 1.2), 0.5)
    assert why == "squeal measured on a pass not flagged squealing"
