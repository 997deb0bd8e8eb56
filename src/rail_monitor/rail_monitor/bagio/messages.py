"""The rail_msgs messages as plain fields, and back: the one place for each conversion (no rclpy).

To a message: each ``*_fields`` function gives a message's fields as a nested dict of Python
values (sub-messages as dicts, arrays as lists), which :func:`rail_monitor.bagio.cdr.serialize`
turns into CDR bytes (batch mode, bag writers) and ``rail_monitor.nodes.convert.to_msg`` into an
rclpy message (the live graph). Fields left out take their zero value.

From a message: the ``*_from_msg`` functions and :func:`pass_row` read rclpy messages and
rosbags' deserialised objects alike (the two have the same attribute names).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from rail_monitor.alerts.manager import Alert
from rail_monitor.core.timeutil import from_sec_nanosec, to_sec_nanosec
from rail_monitor.corrugation.records import Advice, Forecast, StateSnapshot
from rail_monitor.noise.predict import Corrugation, NoisePrediction

Fields = dict[str, Any]
INT32_END_NS = 2**31 * 10**9  # builtin_interfaces/Time's int32 seconds end in January 2038


# -- times and headers ----------------------------------------------------------------------------
def time_fields(ns: int) -> Fields:
    """builtin_interfaces/Time of ns since the epoch."""
    sec, nanosec = to_sec_nanosec(ns)
    return {"sec": sec, "nanosec": nanosec}


def future_time_fields(ns: int) -> Fields:
    """A future time, or zero ("never") past 2038, where Time's int32 seconds end."""
    return time_fields(ns if 0 < ns < INT32_END_NS else 0)


def time_ns(t: Any) -> int:
    """ns since the epoch of a builtin_interfaces/Time."""
    return from_sec_nanosec(t.sec, t.nanosec)


def header_fields(stamp_ns: int, frame_id: str) -> Fields:
    return {"stamp": time_fields(stamp_ns), "frame_id": frame_id}


def header_of(msg: Any) -> Fields:
    """The header of a message as fields (outputs carry their pass's header)."""
    h = msg.header
    return {"stamp": {"sec": h.stamp.sec, "nanosec": h.stamp.nanosec}, "frame_id": h.frame_id}


def stamps_ns(msgs: list[Any]) -> np.ndarray:
    """The header stamps of messages [ns]."""
    return np.array([time_ns(m.header.stamp) for m in msgs], np.int64)


# -- TrainPass ------------------------------------------------------------------------------------
PASS_FIELDS = ("train_id", "vehicle_class", "vehicle_count", "axle_count", "speed_mps", "angle_of_attack_rad",
               "wheel_load_n", "friction_state", "train_length_m")


def train_pass_fields(row: dict[str, Any], frame_id: str) -> Fields:
    """A PassTable row (see PassTable.row) as TrainPass fields."""
    return {"header": header_fields(row["stamp_ns"], frame_id), **{k: row[k] for k in PASS_FIELDS}}


def pass_row(msg: Any) -> dict[str, Any]:
    """A TrainPass as a PassTable row."""
    return {"stamp_ns": time_ns(msg.header.stamp), **{k: getattr(msg, k) for k in PASS_FIELDS}}


# -- model outputs --------------------------------------------------------------------------------
def squeal_prediction_fields(values: dict[str, np.ndarray], i: int, header: Fields, train_id: str) -> Fields:
    """Row i of rail_monitor.squeal.predict.predict as SquealPrediction fields for its pass."""
    return {"header": header, "train_id": train_id, **{k: v[i].item() for k, v in values.items()}}


def corrugation_state_fields(snap: StateSnapshot, fc: Forecast, frame_id: str) -> Fields:
    """A corrugation state (a StateSnapshot, or the estimator itself) and its Forecast as
    CorrugationState fields."""
    return {
        "header": header_fields(snap.newest_ns, frame_id), "last_train_id": snap.newest_train_id,
        "pass_count": snap.pass_count, "axle_pass_count": snap.axle_pass_count,
        "total_pass_count": snap.total_pass_count, "last_grinding_time": time_fields(snap.last_grinding_ns),
        "wavelength_m": snap.bands.tolist(), "amplitude_m": snap.amplitude.tolist(),
        "growth_per_axle_pass": fc.growth_per_axle_pass.tolist(), "threshold_m": snap.threshold.tolist(),
        "post_grinding_m": snap.grinding_amplitude.tolist(), "worst_band": int(fc.worst_band),
        "worst_wavelength_m": float(snap.bands[fc.worst_band]), "passes_to_threshold": float(fc.passes_to_threshold),
        "days_to_threshold": float(fc.days_to_threshold), "passes_per_day": float(fc.passes_per_day),
        "grinding_due": bool(fc.grinding_due), "grinding_due_time": future_time_fields(fc.grinding_due_ns),
        "k_b_by_friction": [float(k) for k in snap.k_b]}


def speed_advisory_fields(advice: Advice, stamp_ns: int, frame_id: str) -> Fields:
    """Speed advice as SpeedAdvisory fields (the message's fields are the record's)."""
    out: Fields = {"header": header_fields(stamp_ns, frame_id)}
    for name, value in vars(advice).items():
        out[name] = value.tolist() if hasattr(value, "tolist") and getattr(value, "ndim", 0) else float(value)
    return out


def rolling_noise_fields(p: NoisePrediction, i: int, header: Fields, train_id: str, receiver: Any) -> Fields:
    """Pass i of a NoisePrediction as RollingNoise fields (receiver: a models.passby.Receiver)."""
    return {
        "header": header, "train_id": train_id, "model": p.model, "speed_mps": float(p.speed_mps[i]),
        "receiver_distance_m": float(receiver.distance_m), "receiver_height_m": float(receiver.height_m),
        "band_centre_hz": p.band_centre_hz.tolist(), "lp_db": p.lp_db[i].tolist(), "lw_db": p.lw_db[i].tolist(),
        "roughness_db": p.roughness_db[i].tolist(), "pass_by_time_s": float(p.pass_by_time_s[i]),
        "lpaeq_tp_dba": float(p.lpaeq_tp_dba[i]), "lpafmax_dba": float(p.lpafmax_dba[i]),
        "tel_dba": float(p.tel_dba[i]), "roughness_growth_increase_db": float(p.roughness_growth_increase_db[i]),
        "component_names": list(p.component_names), "component_lpaeq_dba": p.component_lpaeq_dba[i].tolist()}


def wayside_alert_fields(alert: Alert, frame_id: str) -> Fields:
    """An Alert as WaysideAlert fields."""
    return {"header": header_fields(alert.stamp_ns, frame_id), "kind": alert.kind, "key": alert.key,
            "severity": alert.severity, "active": alert.active, "summary": alert.summary,
            "value": float(alert.value), "threshold": float(alert.threshold), "unit": alert.unit,
            "raised_time": time_fields(alert.raised_ns), "due_time": future_time_fields(alert.due_ns)}


def wayside_alert_array_fields(alerts: list[Alert], stamp_ns: int, frame_id: str) -> Fields:
    """The standing alerts as a WaysideAlertArray snapshot."""
    return {"header": header_fields(stamp_ns, frame_id), "alerts": [wayside_alert_fields(a, frame_id) for a in alerts]}


# -- back to records ------------------------------------------------------------------------------
def alert_from_msg(msg: Any) -> Alert:
    """A WaysideAlert as an Alert."""
    return Alert(msg.kind, msg.key, msg.severity, msg.active, msg.summary, msg.value, msg.threshold, msg.unit,
                 time_ns(msg.header.stamp), time_ns(msg.raised_time), time_ns(msg.due_time))


def corrugation_from_msg(msg: Any) -> Corrugation:
    """The bands and amplitudes of a CorrugationState; ValueError when they are inconsistent. A state
    without post-grinding amplitudes counts growth from zero."""
    wl, amp = np.asarray(msg.wavelength_m, float), np.asarray(msg.amplitude_m, float)
    post = np.asarray(msg.post_grinding_m, float) if len(msg.post_grinding_m) else np.zeros_like(amp)
    if not (len(wl) == len(amp) == len(post)):
        raise ValueError("wavelength_m, amplitude_m and post_grinding_m differ in length")
    if not (np.all(np.isfinite(wl)) and np.all(wl > 0) and np.all(np.isfinite(amp)) and np.all(amp >= 0)
            and np.all(np.isfinite(post)) and np.all(post >= 0)):
        raise ValueError("a wavelength is not positive or an amplitude is negative or not finite")
    return Corrugation(wl, amp, post)


def corrugation_series(msgs: list[Any]) -> dict[str, np.ndarray]:
    """CorrugationStates on the same bands as AlertManager.on_states' arguments: stamps [ns], bands
    [m] and thresholds [m] of the first, amplitudes [m] (states x bands), forecast fields per state."""
    return {"stamp_ns": stamps_ns(msgs), "wavelength_m": np.asarray(msgs[0].wavelength_m),
            "amplitude_m": np.array([m.amplitude_m for m in msgs]), "threshold_m": np.asarray(msgs[0].threshold_m),
            "days_to_threshold": np.array([m.days_to_threshold for m in msgs]),
            "grinding_due": np.array([m.grinding_due for m in msgs]),
            "grinding_due_ns": np.array([time_ns(m.grinding_due_time) for m in msgs], np.int64)}
