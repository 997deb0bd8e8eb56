"""A measured pass-by (rail_msgs/MeasuredPassNoise) and the checks that refuse a bad one.

A measurement is refused, with a one-line reason, when a band level or single number is not
finite or outside 0-150 dB (no train at 7.5 m gives a level outside that), when its bands are not
1/3-octave centres of the model's set, when its receiver is not the model's (within
``residual.receiver_tolerance_m``), when its instrument class is not 1 or 2, or when its vehicle
segments do not pair ids with levels, or when a squeal measure (tone, level, duration; NaN: not
measured) is out of range or given for a pass not flagged squealing.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

LEVEL_RANGE_DB = (0.0, 150.0)
INSTRUMENT_CLASSES = (1, 2)
MAX_VEHICLES = 1000  # segments of one train: more is no train (and would cost memory to check)
SQUEAL_BAND_HZ = (20.0, 20_000.0)  # a squeal's tone is audible sound (measured ones lie in 0.4-10 kHz)
MAX_PASS_S = 3600.0  # no pass-by lasts an hour
MAX_SQUEAL_DISTANCE_M = 1000.0  # squeal.receiver_distance_m's range: no one wheel is heard further
# The squeal measures a measurement may carry, each with its value when not measured.
SQUEAL_MEASURES: dict[str, float | bool] = {"squeal_frequency_hz": float("nan"), "squeal_level_db": float("nan"),
                                            "squeal_duration_s": float("nan"), "flanging_detected": False}


@dataclass(frozen=True)
class Measurement:
    """One measured pass-by (fields and units as in rail_msgs/MeasuredPassNoise)."""

    stamp_ns: int
    train_id: str
    receiver_distance_m: float
    receiver_height_m: float
    instrument_class: int
    band_centre_hz: np.ndarray          # (M,) [Hz]
    leq_db: np.ndarray                  # (M,) [dB re 20 uPa]
    lpaeq_tp_dba: float
    lpafmax_dba: float
    tel_dba: float
    squeal_detected: bool = False
    vehicle_id: tuple[str, ...] = ()
    vehicle_lpaeq_dba: np.ndarray = field(default_factory=lambda: np.zeros(0))
    squeal_frequency_hz: float = float("nan")  # NaN: no squeal, or not measured
    squeal_level_db: float = float("nan")      # [dB re 20 uPa]
    squeal_duration_s: float = float("nan")    # 0: no squeal; NaN: not measured
    flanging_detected: bool = False

    @property
    def key(self) -> tuple[int, str]:
        """The pass it measures: (stamp [ns], train_id)."""
        return self.stamp_ns, self.train_id


def band_index(model_band_hz: np.ndarray, band_hz: np.ndarray) -> np.ndarray:
    """The model band of each measured band (nominal centres within 3 %), -1 where none is
    (read-only: a station sends the same bands with every pass, so each set is matched once)."""
    return _band_index(np.asarray(model_band_hz, float).tobytes(), np.asarray(band_hz, float).tobytes())


@functools.lru_cache(maxsize=64)
def _band_index(model_band_hz: bytes, band_hz: bytes) -> np.ndarray:
    bands, model = np.frombuffer(band_hz), np.frombuffer(model_band_hz)
    ratio = np.abs(np.log(bands[:, None] / model[None, :]))
    nearest = np.argmin(ratio, axis=1)
    out = np.where(ratio[np.arange(len(nearest)), nearest] < 0.03, nearest, -1)
    out.flags.writeable = False
    return out


def measurement_refusal(m: Measurement, model_band_hz: np.ndarray, receiver_m: tuple[float, float],
                        tolerance_m: float) -> str:
    """Why a measurement cannot be compared with the model ('' when it can)."""
    if m.stamp_ns <= 0:
        return "stamp not set, or before 1970"
    bands, leq = np.asarray(m.band_centre_hz, float), np.asarray(m.leq_db, float)
    if bands.ndim != 1 or bands.shape != leq.shape or not len(bands):
        return "band_centre_hz and leq_db differ in length, or are empty"
    if len(bands) > len(model_band_hz) or len(m.vehicle_id) > MAX_VEHICLES:
        return f"more bands than the model's {len(model_band_hz)}, or more than {MAX_VEHICLES} vehicle segments"
    if not (np.all(np.isfinite(bands)) and np.all(bands > 0)):
        return "a band centre is not positive and finite"
    levels = np.array([*leq.tolist(), m.lpaeq_tp_dba, m.lpafmax_dba, m.tel_dba])
    if not np.all(np.isfinite(levels)):
        return "a band level or single number is not finite"
    lo, hi = LEVEL_RANGE_DB
    if np.any(levels < lo) or np.any(levels > hi):
        return f"a level is outside {lo:g}-{hi:g} dB"
    index = band_index(model_band_hz, bands)
    if np.any(index < 0) or len(set(index.tolist())) != len(index):
        return "a band is not a 1/3-octave centre of the model's 50 Hz-10 kHz set, or is given twice"
    distance, height = receiver_m
    if not (abs(m.receiver_distance_m - distance) <= tolerance_m and abs(m.receiver_height_m - height) <= tolerance_m):
        return f"receiver ({m.receiver_distance_m:g} m, {m.receiver_height_m:g} m) is not the model's " \
               f"({distance:g} m, {height:g} m)"
    if m.instrument_class not in INSTRUMENT_CLASSES:
        return f"instrument class {m.instrument_class} is not 1 or 2"
    seg = np.asarray(m.vehicle_lpaeq_dba, float)
    if len(m.vehicle_id) != len(seg) or not np.all(np.isfinite(seg) & (seg >= lo) & (seg <= hi)):
        return "vehicle_id and vehicle_lpaeq_dba differ in length, or a vehicle level is not a level"
    return squeal_refusal(m)


def squeal_observation_refusal(m: Measurement) -> str:
    """Why a measurement cannot tell whether its pass squealed, and how loud ('' when it can): its
    stamp, its microphone's distance and its squeal measures (its band levels are not needed)."""
    if m.stamp_ns <= 0:
        return "stamp not set, or before 1970"
    if not (np.isfinite(m.receiver_distance_m) and 0.0 < m.receiver_distance_m <= MAX_SQUEAL_DISTANCE_M):
        return f"receiver distance not within 0-{MAX_SQUEAL_DISTANCE_M:g} m"
    return squeal_refusal(m)


def squeal_refusal(m: Measurement) -> str:
    """Why a measurement's squeal measures are not measures ('' when they are, NaN: not measured)."""
    f, level, duration = m.squeal_frequency_hz, m.squeal_level_db, m.squeal_duration_s
    lo, hi = LEVEL_RANGE_DB
    if not (np.isnan(f) or SQUEAL_BAND_HZ[0] <= f <= SQUEAL_BAND_HZ[1]) or not (np.isnan(level) or lo <= level <= hi) \
            or not (np.isnan(duration) or 0.0 <= duration <= MAX_PASS_S):
        return (f"a squeal measure is out of range (tone {SQUEAL_BAND_HZ[0]:g}-{SQUEAL_BAND_HZ[1]:g} Hz, level "
                f"{lo:g}-{hi:g} dB, duration 0-{MAX_PASS_S:g} s)")
    if not m.squeal_detected and (np.isfinite(f) or np.isfinite(level) or duration > 0.0):
        return "squeal measured on a pass not flagged squealing"
    return ""
