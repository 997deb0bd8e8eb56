"""The ``station.*`` parameters: where a station's recorder leaves each pass's audio, its
calibration and microphone, the squeal detector's thresholds and the audio archive's budget."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from rail_monitor.core.params import ParamSpec, section_values

STATION_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("audio_folder", "", "Folder the station's recorder leaves each pass's audio in, one WAV per pass "
              "named <UTC stamp>_<train_id>.wav (station.pass_audio.audio_name); never written to."),
    ParamSpec("lead_s", 5.0, "Time from a file's start to its pass's stamp (the leading axle at the microphone) "
              "[s].", 0.0, 600.0),
    ParamSpec("audio_wait_s", 30.0, "Longest wall time a pass waits for its audio to appear; then it is counted "
              "as not heard [s].", 0.0, 86_400.0),
    ParamSpec("sensitivity_pa_per_unit", 0.0, "Pascals per full-scale unit of the recordings; 0: from "
              "calibration_file [Pa].", 0.0, 1.0e6),
    ParamSpec("calibration_file", "", "A recording of a calibrator on the same channel (WAV), when "
              "sensitivity_pa_per_unit is 0."),
    ParamSpec("calibration_db", 94.0, "The calibrator's level [dB re 20 uPa].", 60.0, 140.0),
    ParamSpec("channel", 0, "The channel of a multi-channel recording (0 first) [-].", 0, 63),
    ParamSpec("instrument_class", 1, "IEC 61672-1 performance class of the measuring chain (1 or 2) [-].", 1, 2),
    ParamSpec("microphone_distance_m", 7.5, "Horizontal distance of the microphone from the track centre "
              "(ISO 3095: 7.5 m) [m].", 0.5, 1000.0),
    ParamSpec("microphone_height_m", 1.2, "Microphone height above the rail head (ISO 3095: 1.2 m) [m].",
              -10.0, 100.0),
    ParamSpec("squeal_min_audibility_db", 6.0, "A frame squeals when a tone of 400 Hz-10 kHz is this audible "
              "(ISO/PAS 20065 audibility; any value above 0 is audible) [dB].", 0.0, 40.0),
    ParamSpec("squeal_min_duration_s", 0.5, "A pass squeals when such a tone holds this long [s].", 0.1, 60.0),
    ParamSpec("archive_folder", "", "Folder the audio of passes worth hearing is copied into ('': none kept). "
              "Only files the station put there are ever deleted."),
    ParamSpec("archive_budget_mb", 1024.0, "Disk the archive may use [MiB].", 0.0, 1.0e7),
    ParamSpec("loudest_per_day", 10, "Keep the audio of this many loudest passes (LpAFmax) of each UTC day [-].",
              0, 100_000),
)


@dataclass(frozen=True)
class StationConfig:
    """Station parameters (names and units as in STATION_SPECS)."""

    audio_folder: str
    lead_s: float
    audio_wait_s: float
    sensitivity_pa_per_unit: float
    calibration_file: str
    calibration_db: float
    channel: int
    instrument_class: int
    microphone_distance_m: float
    microphone_height_m: float
    squeal_min_audibility_db: float
    squeal_min_duration_s: float
    archive_folder: str
    archive_budget_mb: float
    loudest_per_day: int


def station_config(values: Mapping[str, Any], prefix: str = "station.") -> StationConfig:
    """Checked station parameters from flat values (keys under prefix)."""
    return section_values(StationConfig, STATION_SPECS, values, prefix)
