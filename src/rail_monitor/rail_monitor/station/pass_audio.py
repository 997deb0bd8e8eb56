"""One pass's recorded audio reduced to what a noise station reports: its ISO 3095 levels and
1/3-octave bands (models.iso3095), its squeal and flanging (models.squeal_detection), as a
Measurement (rail_msgs/MeasuredPassNoise) of the pass it records.

A station's recorder leaves one WAV per pass in a folder, named after the pass it holds
(:func:`audio_name`: the pass's stamp in UTC to the nanosecond, then its train id), the file
starting ``lead_s`` before the pass's stamp (its leading axle at the microphone). The pass-by
time Tp is the train's length over its speed (ISO 3095:2013, 3.6: from the front's passage of the
microphone to the rear's), so the pass lies between lead_s and lead_s + Tp of the file.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import numpy as np

from rail_monitor.bagio.wav import read_wav
from rail_monitor.core.errors import InputError, RailMonitorError
from rail_monitor.core.timeutil import NS_PER_S
from rail_monitor.measured.records import Measurement
from rail_monitor.models.iso3095 import PassbyLevels, passby_levels, sensitivity_pa_per_unit
from rail_monitor.models.squeal_detection import SquealDetection, detect_squeal
from rail_monitor.station.config import StationConfig

_UNSAFE = re.compile(r"[^A-Za-z0-9._-]")


def audio_name(stamp_ns: int, train_id: str) -> str:
    """The file name of a pass's audio: '<YYYYmmddTHHMMSS>.<ns, 9 digits>Z_<train_id>.wav' (UTC;
    a character of the train id outside letters, digits, '.', '_' and '-' becomes '_')."""
    sec, frac = divmod(int(stamp_ns), NS_PER_S)
    stamp = datetime.fromtimestamp(sec, UTC).strftime("%Y%m%dT%H%M%S")
    return f"{stamp}.{frac:09d}Z_{_UNSAFE.sub('_', train_id)}.wav"


def sensitivity(scale_pa: float, calibration_file: str | Path | None, calibration_db: float, channel: int) -> float:
    """Pascals per full-scale unit: scale_pa when positive, else from a calibrator's recording
    (RailMonitorError, one line, when neither gives one)."""
    if scale_pa > 0.0:
        if not np.isfinite(scale_pa):
            raise RailMonitorError(f"the sensitivity must be a positive number of pascals, not {scale_pa:g}")
        return float(scale_pa)
    if not calibration_file:
        raise RailMonitorError("give a sensitivity in pascals, or a calibrator's recording")
    _, cal = read_wav(calibration_file, channel)
    try:
        return sensitivity_pa_per_unit(cal, calibration_db)
    except ValueError as exc:
        raise InputError(f"{calibration_file}: {exc}") from None


@dataclass(frozen=True)
class HeardPass:
    levels: PassbyLevels
    squeal: SquealDetection


def hear(path: str | Path, scale_pa: float, channel: int = 0, start_s: float | None = None,
         end_s: float | None = None, min_duration_s: float = 0.5, min_audibility_db: float = 6.0) -> HeardPass:
    """The levels and squeal of the pass between start_s and end_s [s] (default: the whole file)
    of a recording in full-scale units times scale_pa [Pa per unit] (InputError naming the file for
    a recording that cannot be reduced)."""
    fs, samples = read_wav(path, channel)
    pressure = samples * scale_pa
    try:
        return HeardPass(passby_levels(pressure, fs, start_s, end_s),
                         detect_squeal(pressure, fs, start_s, end_s, min_duration_s, min_audibility_db))
    except ValueError as exc:
        raise InputError(f"{path}: {exc}") from None


def hear_pass(path: str | Path, scale_pa: float, cfg: StationConfig, pass_time_s: float) -> HeardPass:
    """A pass's audio as the station hears it: the pass lies from lead_s to lead_s + pass_time_s
    (Tp [s]) of the file."""
    return hear(path, scale_pa, cfg.channel, cfg.lead_s, cfg.lead_s + pass_time_s, cfg.squeal_min_duration_s,
                cfg.squeal_min_audibility_db)


def measurement(stamp_ns: int, train_id: str, heard: HeardPass, cfg: StationConfig) -> Measurement:
    """The measured pass-by of a heard pass, as the station sends it."""
    lv, sq = heard.levels, heard.squeal
    return Measurement(
        stamp_ns=int(stamp_ns), train_id=train_id, receiver_distance_m=cfg.microphone_distance_m,
        receiver_height_m=cfg.microphone_height_m, instrument_class=cfg.instrument_class,
        band_centre_hz=np.asarray(lv.band_centres_hz, float), leq_db=np.asarray(lv.band_levels_db, float),
        lpaeq_tp_dba=lv.lpaeq_tp_db, lpafmax_dba=lv.lpafmax_db, tel_dba=lv.tel_db, squeal_detected=sq.squeal,
        squeal_frequency_hz=sq.frequency_hz, squeal_level_db=sq.level_db, squeal_duration_s=sq.duration_s,
        flanging_detected=sq.flanging)
