"""Conversions between rail_msgs messages and the pure tables: the one place for each."""

from __future__ import annotations

from typing import Any

import numpy as np
from builtin_interfaces.msg import Time

from rail_monitor.nodes.qos import ALERT_QOS, LATEST_QOS, STATE_QOS, STREAM_QOS
from rail_monitor.rolling_noise import Corrugation
from rail_monitor.timeutil import from_sec_nanosec, to_sec_nanosec
from rail_msgs.msg import (
    CorrugationState,
    RollingNoise,
    SpeedAdvisory,
    SquealPrediction,
    TrainPass,
    WaysideAlert,
    WaysideAlertArray,
)

# The graph's recorded topics (relative to the site namespace): message type and publisher QoS.
GRAPH_TOPICS: dict[str, tuple[type, Any]] = {
    "train_pass": (TrainPass, STREAM_QOS), "noise/squeal": (SquealPrediction, STREAM_QOS),
    "corrugation/state": (CorrugationState, STATE_QOS), "noise/rolling": (RollingNoise, STREAM_QOS),
    "alerts": (WaysideAlert, ALERT_QOS), "alerts/standing": (WaysideAlertArray, LATEST_QOS),
    "speed_advisory": (SpeedAdvisory, LATEST_QOS)}


def typename(msg_type: type) -> str:
    """A generated message class's ROS type name, e.g. rail_msgs/msg/TrainPass."""
    return f"{msg_type.__module__.split('.')[0]}/msg/{msg_type.__name__}"


def time_msg(ns: int) -> Time:
    sec, nanosec = to_sec_nanosec(ns)
    return Time(sec=sec, nanosec=nanosec)


def time_ns(t: Time) -> int:
    return from_sec_nanosec(t.sec, t.nanosec)


def _time_or_never(ns: int) -> Time:
    """A future time; zero ("never") past 2038, where builtin_interfaces/Time's int32 seconds end."""
    return time_msg(ns if 0 < ns < 2**31 * 10**9 else 0)


def train_pass_msg(row: dict[str, Any], frame_id: str) -> TrainPass:
    """A PassTable row (see PassTable.row) as a TrainPass message."""
    msg = TrainPass()
    msg.header.stamp = time_msg(row["stamp_ns"])
    msg.header.frame_id = frame_id
    msg.train_id = row["train_id"]
    msg.vehicle_class = row["vehicle_class"]
    msg.vehicle_count = row["vehicle_count"]
    msg.axle_count = row["axle_count"]
    msg.speed_mps = row["speed_mps"]
    msg.angle_of_attack_rad = row["angle_of_attack_rad"]
    msg.wheel_load_n = row["wheel_load_n"]
    msg.friction_state = row["friction_state"]
    msg.train_length_m = row["train_length_m"]
    return msg


def train_pass_row(msg: TrainPass) -> dict[str, Any]:
    """A TrainPass message as a PassTable row."""
    return {
        "stamp_ns": time_ns(msg.header.stamp), "train_id": msg.train_id, "vehicle_class": msg.vehicle_class,
        "vehicle_count": msg.vehicle_count, "axle_count": msg.axle_count, "speed_mps": msg.speed_mps,
        "angle_of_attack_rad": msg.angle_of_attack_rad, "wheel_load_n": msg.wheel_load_n,
        "friction_state": msg.friction_state, "train_length_m": msg.train_length_m,
    }


_CASTS = {"boolean": bool, "float": float, "double": float, "string": str}


def fill_fields(msg: Any, values: dict[str, Any], i: int) -> Any:
    """Set msg's fields from row i of a dict of model output arrays (keys = field names).

    Scalars are cast to the field's Python type (numpy scalars are refused by rclpy's setters).
    """
    types = msg.get_fields_and_field_types()
    for name, column in values.items():
        cast = _CASTS.get(types[name], int)
        setattr(msg, name, cast(column[i]))
    return msg


def squeal_prediction_msg(values: dict[str, Any], i: int, source: TrainPass) -> SquealPrediction:
    """Row i of rail_monitor.squeal_risk.predict as a SquealPrediction for the pass source."""
    msg = SquealPrediction(header=source.header, train_id=source.train_id)
    return fill_fields(msg, values, i)


def corrugation_state_msg(est: Any, fc: Any, frame_id: str) -> CorrugationState:
    """A rail_monitor.corrugation_state.CorrugationEstimator (or a StateSnapshot of one) and its
    Forecast as a CorrugationState."""
    msg = CorrugationState()
    msg.header.stamp = time_msg(est.newest_ns)
    msg.header.frame_id = frame_id
    msg.last_train_id = est.newest_train_id
    msg.pass_count, msg.axle_pass_count = est.pass_count, est.axle_pass_count
    msg.total_pass_count = est.total_pass_count
    msg.last_grinding_time = time_msg(est.last_grinding_ns)
    msg.wavelength_m = est.bands.tolist()
    msg.amplitude_m = est.amplitude.tolist()
    msg.growth_per_axle_pass = fc.growth_per_axle_pass.tolist()
    msg.threshold_m = est.threshold.tolist()
    msg.post_grinding_m = est.grinding_amplitude.tolist()
    msg.worst_band = fc.worst_band
    msg.worst_wavelength_m = float(est.bands[fc.worst_band])
    msg.passes_to_threshold = float(fc.passes_to_threshold)
    msg.days_to_threshold = float(fc.days_to_threshold)
    msg.passes_per_day = float(fc.passes_per_day)
    msg.grinding_due = fc.grinding_due
    msg.grinding_due_time = _time_or_never(fc.grinding_due_ns)
    msg.k_b_by_friction = [float(k) for k in est.k_b]
    return msg


def speed_advisory_msg(advice: Any, stamp_ns: int, frame_id: str) -> SpeedAdvisory:
    """A rail_monitor.corrugation_state.Advice as a SpeedAdvisory."""
    msg = SpeedAdvisory()
    msg.header.stamp = time_msg(stamp_ns)
    msg.header.frame_id = frame_id
    for name, value in vars(advice).items():
        setattr(msg, name, value.tolist() if hasattr(value, "tolist") and getattr(value, "ndim", 0) else float(value))
    return msg


def rolling_noise_msg(values: dict[str, Any], i: int, source: TrainPass, receiver: Any) -> RollingNoise:
    """Row i of rail_monitor.rolling_noise.RollingNoiseModel.predict as a RollingNoise for the pass source
    (receiver: a models.passby.Receiver)."""
    msg = RollingNoise(header=source.header, train_id=source.train_id, model=values["model"],
                       receiver_distance_m=float(receiver.distance_m), receiver_height_m=float(receiver.height_m))
    msg.band_centre_hz = values["band_centre_hz"].tolist()
    for name in ("lp_db", "lw_db", "roughness_db"):
        setattr(msg, name, values[name][i].tolist())
    for name in ("speed_mps", "pass_by_time_s", "lpaeq_tp_dba", "lpafmax_dba", "tel_dba",
                 "roughness_growth_increase_db"):
        setattr(msg, name, float(values[name][i]))
    msg.component_names = list(values["component_names"])
    msg.component_lpaeq_dba = values["component_lpaeq_dba"][i].tolist()
    return msg


def corrugation_from_msg(msg: CorrugationState) -> Corrugation:
    """The bands and amplitudes of a CorrugationState (rail_monitor.rolling_noise.Corrugation); ValueError
    when they are inconsistent. A state without post-grinding amplitudes counts growth from zero."""
    wl, amp = np.asarray(msg.wavelength_m, float), np.asarray(msg.amplitude_m, float)
    post = np.asarray(msg.post_grinding_m, float) if len(msg.post_grinding_m) else np.zeros_like(amp)
    if not (len(wl) == len(amp) == len(post)):
        raise ValueError("wavelength_m, amplitude_m and post_grinding_m differ in length")
    if not (np.all(np.isfinite(wl)) and np.all(wl > 0) and np.all(np.isfinite(amp)) and np.all(amp >= 0)
            and np.all(np.isfinite(post)) and np.all(post >= 0)):
        raise ValueError("a wavelength is not positive or an amplitude is negative or not finite")
    return Corrugation(wl, amp, post)


def stamps_ns(msgs: list[Any]) -> np.ndarray:
    """The header stamps of messages [ns]."""
    return np.array([time_ns(m.header.stamp) for m in msgs], np.int64)


def corrugation_series(msgs: list[CorrugationState]) -> dict[str, np.ndarray]:
    """States on the same bands as AlertManager.on_states' arguments: stamps [ns], bands [m] and
    thresholds [m] of the first, amplitudes [m] (states x bands), forecast fields per state."""
    return {"stamp_ns": stamps_ns(msgs), "wavelength_m": np.asarray(msgs[0].wavelength_m),
            "amplitude_m": np.array([m.amplitude_m for m in msgs]), "threshold_m": np.asarray(msgs[0].threshold_m),
            "days_to_threshold": np.array([m.days_to_threshold for m in msgs]),
            "grinding_due": np.array([m.grinding_due for m in msgs]),
            "grinding_due_ns": np.array([time_ns(m.grinding_due_time) for m in msgs], np.int64)}


def wayside_alert_msg(alert: Any, frame_id: str) -> WaysideAlert:
    """A rail_monitor.alerts.Alert as a WaysideAlert."""
    msg = WaysideAlert(kind=alert.kind, key=alert.key, severity=alert.severity, active=alert.active,
                       summary=alert.summary, value=float(alert.value), threshold=float(alert.threshold),
                       unit=alert.unit, raised_time=time_msg(alert.raised_ns), due_time=_time_or_never(alert.due_ns))
    msg.header.stamp = time_msg(alert.stamp_ns)
    msg.header.frame_id = frame_id
    return msg


def wayside_alert_array_msg(alerts: list[Any], stamp_ns: int, frame_id: str) -> WaysideAlertArray:
    """The standing alerts (rail_monitor.alerts.Alert) as a WaysideAlertArray snapshot."""
    msg = WaysideAlertArray(alerts=[wayside_alert_msg(a, frame_id) for a in alerts])
    msg.header.stamp = time_msg(stamp_ns)
    msg.header.frame_id = frame_id
    return msg


def alert_from_msg(msg: WaysideAlert) -> Any:
    """A WaysideAlert back as a rail_monitor.alerts.Alert."""
    from rail_monitor.alerts import Alert

    return Alert(msg.kind, msg.key, msg.severity, msg.active, msg.summary, msg.value, msg.threshold, msg.unit,
                 time_ns(msg.header.stamp), time_ns(msg.raised_time), time_ns(msg.due_time))
