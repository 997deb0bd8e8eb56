"""The rail_msgs messages as plain fields, and back: the one place for each conversion (no rclpy).

To a message: each ``*_fields`` function gives a message's fields as a nested dict of Python
values (sub-messages as dicts, arrays as lists), which :func:`rail_monitor.codec.cdr.serialize`
turns into CDR bytes (batch mode, bag writers) and ``rail_monitor.nodes.convert.to_msg`` into an
rclpy message (the live graph). Fields left out take their zero value.

From a message: the ``*_from_msg`` functions and :func:`pass_row` read rclpy messages and
rosbags' deserialised objects alike (the two have the same attribute names);
:func:`passes_from_columns` reads TrainPasses taken together (codec.cdr_columns).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable
from dataclasses import fields as dataclass_fields
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from rail_monitor.alerts.manager import Alert
from rail_monitor.codec.cdr_from_columns import serialize_columns
from rail_monitor.codec.typestore import CORRUGATION_STATE, ROLLING_NOISE
from rail_monitor.core.friction import FRICTION_NAMES
from rail_monitor.core.passes import PassTable
from rail_monitor.core.timeutil import NS_PER_S, TIME_MSG_END_NS, from_sec_nanosec, to_sec_nanosec
from rail_monitor.corrugation.records import Forecast, StateSnapshot, Trajectory
from rail_monitor.measured.records import SQUEAL_MEASURES, Measurement
from rail_monitor.measured.residuals import Residual
from rail_monitor.noise.records import NoisePrediction

if TYPE_CHECKING:
    from rail_monitor.advice.plan import SpeedAdvice
    from rail_monitor.engine.squeal_site import Calibration
    from rail_monitor.measured.observer import Observation

Fields = dict[str, Any]


# -- times and headers ----------------------------------------------------------------------------
def time_fields(ns: int) -> Fields:
    """builtin_interfaces/Time of ns since the epoch."""
    sec, nanosec = to_sec_nanosec(ns)
    return {"sec": sec, "nanosec": nanosec}


def future_time_fields(ns: int) -> Fields:
    """A future time, or zero ("never") past 2038, where Time's int32 seconds end."""
    return time_fields(ns if 0 < ns < TIME_MSG_END_NS else 0)


def time_ns(t: Any) -> int:
    """ns since the epoch of a builtin_interfaces/Time."""
    return from_sec_nanosec(t.sec, t.nanosec)


def header_fields(stamp_ns: int, frame_id: str) -> Fields:
    return {"stamp": time_fields(stamp_ns), "frame_id": frame_id}


def header_of(msg: Any) -> Fields:
    """The header of a message as fields (outputs carry their pass's header)."""
    h = msg.header
    return {"stamp": {"sec": h.stamp.sec, "nanosec": h.stamp.nanosec}, "frame_id": h.frame_id}


# -- TrainPass ------------------------------------------------------------------------------------
PASS_FIELDS = ("train_id", "vehicle_class", "vehicle_count", "axle_count", "speed_mps", "angle_of_attack_rad",
               "wheel_load_n", "friction_state", "train_length_m")


def train_pass_fields(row: dict[str, Any], frame_id: str) -> Fields:
    """A PassTable row (see PassTable.row) as TrainPass fields."""
    return {"header": header_fields(row["stamp_ns"], frame_id), **{k: row[k] for k in PASS_FIELDS}}


def pass_row(msg: Any) -> dict[str, Any]:
    """A TrainPass as a PassTable row."""
    return {"stamp_ns": time_ns(msg.header.stamp), **{k: getattr(msg, k) for k in PASS_FIELDS}}


class PassHead(NamedTuple):
    """What a model's outputs take from their TrainPass: its stamp [ns], its header as fields
    (stamp and frame_id as sent) and its train_id."""

    stamp_ns: int
    header: Fields
    train_id: str


def passes_from_columns(values: Any) -> tuple[PassTable, list[PassHead]]:
    """TrainPasses read as columns (codec.cdr_columns.read_columns) as a PassTable, and their heads."""
    stamp = values.header.stamp
    stamp_ns = time_columns_ns(stamp)
    table = PassTable(stamp_ns=stamp_ns, **{k: np.array(v, object) if isinstance(v, list) else v
                                            for k in PASS_FIELDS for v in [getattr(values, k)]})
    heads = [PassHead(ns, {"stamp": {"sec": s, "nanosec": n}, "frame_id": f}, t) for ns, s, n, f, t in zip(
        stamp_ns.tolist(), stamp.sec.tolist(), stamp.nanosec.tolist(), values.header.frame_id, values.train_id,
        strict=True)]
    return table, heads


# -- model outputs --------------------------------------------------------------------------------
def squeal_prediction_fields(values: dict[str, np.ndarray], i: int, header: Fields, train_id: str) -> Fields:
    """Row i of rail_monitor.squeal.predict.predict as SquealPrediction fields for its pass."""
    return {"header": header, "train_id": train_id, **{k: v[i].item() for k, v in values.items()}}


def heads_columns(heads: list[PassHead]) -> Fields:
    """The header and train_id of each pass's output, as columns (codec.cdr_from_columns)."""
    return {"header": {"stamp": {"sec": [h.header["stamp"]["sec"] for h in heads],
                                 "nanosec": [h.header["stamp"]["nanosec"] for h in heads]},
                       "frame_id": [h.header["frame_id"] for h in heads]},
            "train_id": [h.train_id for h in heads]}


def table_heads_columns(table: PassTable, frame_id: str) -> Fields:
    """heads_columns of the passes of a table, sent with frame_id (their TrainPasses' header and train_id)."""
    return {"header": {"stamp": time_columns(table.stamp_ns), "frame_id": [frame_id] * len(table)},
            "train_id": [str(t) for t in table.train_id]}


def train_pass_columns(table: PassTable, frame_id: str) -> Fields:
    """A PassTable as TrainPass columns (train_pass_fields, row by row)."""
    return {**table_heads_columns(table, frame_id), "vehicle_class": [str(c) for c in table.vehicle_class],
            **{k: getattr(table, k) for k in PASS_FIELDS if k not in ("train_id", "vehicle_class")}}


def squeal_prediction_columns(values: dict[str, np.ndarray], heads: Fields) -> Fields:
    """rail_monitor.squeal.predict.predict's rows as SquealPrediction columns for their passes
    (heads: their heads_columns)."""
    return {**heads, **values}


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
        "k_b_by_friction": [float(k) for k in snap.k_b], "k_b_p10_by_friction": [float(k) for k in snap.k_b_p10],
        "k_b_p90_by_friction": [float(k) for k in snap.k_b_p90], "calibration_surveys": int(snap.calibration_surveys)}


def time_columns(ns: np.ndarray) -> Fields:
    """builtin_interfaces/Time columns of ns since the epoch (time_fields, element by element)."""
    sec, nanosec = np.divmod(np.asarray(ns, np.int64), NS_PER_S)
    return {"sec": sec, "nanosec": nanosec}


def time_columns_ns(t: Any) -> np.ndarray:
    """ns since the epoch of builtin_interfaces/Time columns (time_ns, element by element; int64)."""
    return t.sec.astype(np.int64) * NS_PER_S + t.nanosec.astype(np.int64)


def corrugation_state_columns(traj: Trajectory, frame_id: str) -> list[tuple[Fields, int]]:
    """The state after each counted pass of a Trajectory as CorrugationState columns
    (corrugation_state_fields, state by state): (columns, states) per run of constants in force."""
    f, out = traj.forecast, []
    cuts = [0, *[first for first, _ in traj.constants_from if 0 < first < len(traj)], len(traj)]
    for lo, hi in itertools.pairwise(cuts):
        if hi <= lo:
            continue
        c, n, rows = traj.constants_at(lo), hi - lo, slice(lo, hi)
        due = f.grinding_due_ns[rows]
        out.append(({
            "header": {"stamp": time_columns(traj.stamp_ns[rows]), "frame_id": [frame_id] * n},
            "last_train_id": [str(t) for t in traj.train_id[rows]], "pass_count": traj.pass_count[rows],
            "axle_pass_count": traj.axle_pass_count[rows], "total_pass_count": traj.total_pass_count[rows],
            "last_grinding_time": time_columns(np.full(n, c.last_grinding_ns)),
            "wavelength_m": np.broadcast_to(c.bands, (n, len(c.bands))), "amplitude_m": traj.amplitude[rows],
            "growth_per_axle_pass": f.growth_per_axle_pass[rows],
            "threshold_m": np.broadcast_to(c.threshold, (n, len(c.threshold))),
            "post_grinding_m": np.broadcast_to(c.grinding_amplitude, (n, len(c.grinding_amplitude))),
            "worst_band": f.worst_band[rows], "worst_wavelength_m": np.asarray(c.bands)[f.worst_band[rows]],
            "passes_to_threshold": f.passes_to_threshold[rows], "days_to_threshold": f.days_to_threshold[rows],
            "passes_per_day": f.passes_per_day[rows], "grinding_due": f.grinding_due[rows],
            "grinding_due_time": time_columns(np.where((due > 0) & (due < TIME_MSG_END_NS), due, 0)),
            **{name: np.broadcast_to(np.asarray(k, float), (n, len(k))) for name, k in (
                ("k_b_by_friction", c.k_b), ("k_b_p10_by_friction", c.k_b_p10), ("k_b_p90_by_friction", c.k_b_p90))},
            "calibration_surveys": np.full(n, c.calibration_surveys)}, n))
    return out


def corrugation_state_cdr(traj: Trajectory, frame_id: str) -> list[bytes]:
    """The CDR bytes of the state after each counted pass of a Trajectory, in order."""
    return [data for columns, n in corrugation_state_columns(traj, frame_id)
            for data in serialize_columns(CORRUGATION_STATE, columns, n)]


def speed_advisory_fields(advice: SpeedAdvice, stamp_ns: int, frame_id: str) -> Fields:
    """Speed advice as SpeedAdvisory fields (the message's fields are the record's)."""
    out: Fields = {"header": header_fields(stamp_ns, frame_id)}
    for name, value in vars(advice).items():
        if isinstance(value, list):
            out[name] = [str(v) for v in value]
        elif isinstance(value, np.ndarray):
            out[name] = value.astype(float).tolist()
        else:
            out[name] = float(value)
    return out


def rolling_noise_columns(p: NoisePrediction, heads: Fields, receiver: Any) -> Fields:
    """A NoisePrediction of the passes as RollingNoise columns (rolling_noise_fields, pass by pass;
    heads: the passes' heads_columns)."""
    n = len(heads["train_id"])
    names, levels = p.components_of_all()
    return {**heads, "model": [p.model] * n, "speed_mps": p.speed_mps,
            "receiver_distance_m": np.full(n, float(receiver.distance_m)),
            "receiver_height_m": np.full(n, float(receiver.height_m)),
            "band_centre_hz": np.broadcast_to(p.band_centre_hz, (n, len(p.band_centre_hz))), "lp_db": p.lp_db,
            "lw_db": p.lw_db, "roughness_db": p.roughness_db, "pass_by_time_s": p.pass_by_time_s,
            "lpaeq_tp_dba": p.lpaeq_tp_dba, "lpafmax_dba": p.lpafmax_dba, "tel_dba": p.tel_dba,
            "roughness_growth_increase_db": p.roughness_growth_increase_db,
            "component_names": names, "component_lpaeq_dba": levels}


def rolling_noise_cdr(predictions: Iterable[NoisePrediction], heads: Fields, receiver: Any) -> list[bytes]:
    """The CDR bytes of every model's RollingNoise of the passes (heads: their heads_columns), pass
    by pass, the models in turn: the order the graph publishes and records them in."""
    n = len(heads["train_id"])
    per_model = [serialize_columns(ROLLING_NOISE, rolling_noise_columns(p, heads, receiver), n) for p in predictions]
    return [data for datas in zip(*per_model, strict=True) for data in datas]


def rolling_noise_fields(p: NoisePrediction, i: int, header: Fields, train_id: str, receiver: Any) -> Fields:
    """Pass i of a NoisePrediction as RollingNoise fields (receiver: a models.passby.Receiver)."""
    names, values = p.components(i)
    return {
        "header": header, "train_id": train_id, "model": p.model, "speed_mps": float(p.speed_mps[i]),
        "receiver_distance_m": float(receiver.distance_m), "receiver_height_m": float(receiver.height_m),
        "band_centre_hz": p.band_centre_hz.tolist(), "lp_db": p.lp_db[i].tolist(), "lw_db": p.lw_db[i].tolist(),
        "roughness_db": p.roughness_db[i].tolist(), "pass_by_time_s": float(p.pass_by_time_s[i]),
        "lpaeq_tp_dba": float(p.lpaeq_tp_dba[i]), "lpafmax_dba": float(p.lpafmax_dba[i]),
        "tel_dba": float(p.tel_dba[i]), "roughness_growth_increase_db": float(p.roughness_growth_increase_db[i]),
        "component_names": names, "component_lpaeq_dba": values}


def wayside_alert_fields(alert: Alert, frame_id: str) -> Fields:
    """An Alert as WaysideAlert fields."""
    return {"header": header_fields(alert.stamp_ns, frame_id), "kind": alert.kind, "key": alert.key,
            "severity": alert.severity, "active": alert.active, "summary": alert.summary,
            "value": float(alert.value), "threshold": float(alert.threshold), "unit": alert.unit,
            "raised_time": time_fields(alert.raised_ns), "due_time": future_time_fields(alert.due_ns)}


def wayside_alert_array_fields(alerts: list[Alert], stamp_ns: int, frame_id: str) -> Fields:
    """The standing alerts as a WaysideAlertArray snapshot."""
    return {"header": header_fields(stamp_ns, frame_id), "alerts": [wayside_alert_fields(a, frame_id) for a in alerts]}


def indirect_roughness_fields(obs: Observation, frame_id: str) -> Fields:
    ind = obs.indirect
    return {"header": header_fields(obs.stamp_ns, frame_id), "window_days": obs.window_days,
            "measured_passes": obs.measured_passes, "wavelength_m": ind.wavelength_m.tolist(),
            "level_db": ind.level_db.tolist(), "sd_db": ind.sd_db.tolist(), "model_db": ind.model_db.tolist(),
            "pass_bands": ind.passes.astype(int).tolist(), "rail_share": ind.rail_share.tolist(),
            "observed_amplitude_m": obs.observed_amplitude_m.tolist()}


def squeal_calibration_fields(c: Calibration, frame_id: str) -> Fields:
    """One fit of the squeal model: per friction state fitted, its configured curve and quantiles."""
    out: Fields = {"header": header_fields(c.stamp_ns, frame_id),
                   "friction_state": [FRICTION_NAMES[code] for code, *_ in c.states],
                   "k1_configured": [k[0] for _, k, *_ in c.states], "k2_configured": [k[1] for _, k, *_ in c.states],
                   "measured_passes": [q.passes for _, _, q, _ in c.states],
                   "squealing_passes": [q.squealed for _, _, q, _ in c.states],
                   "window_passes": [w.passes if w else 0 for *_, w in c.states],
                   "window_squealing": [w.squealed if w else 0 for *_, w in c.states]}
    for i, p in enumerate(("p10", "p50", "p90")):
        out[f"k1_{p}"] = [q.k1[i] for _, _, q, _ in c.states]
        out[f"k2_{p}"] = [q.k2[i] for _, _, q, _ in c.states]
        out[f"window_share_{p}"] = [w.predicted[i] if w else float("nan") for *_, w in c.states]
    return out


def measured_pass_noise_fields(m: Measurement, frame_id: str) -> Fields:
    return {"header": header_fields(m.stamp_ns, frame_id), "train_id": m.train_id,
            "receiver_distance_m": m.receiver_distance_m, "receiver_height_m": m.receiver_height_m,
            "instrument_class": m.instrument_class, "band_centre_hz": np.asarray(m.band_centre_hz, float).tolist(),
            "leq_db": np.asarray(m.leq_db, float).tolist(), "lpaeq_tp_dba": m.lpaeq_tp_dba,
            "lpafmax_dba": m.lpafmax_dba, "tel_dba": m.tel_dba, "squeal_detected": m.squeal_detected,
            "vehicle_id": list(m.vehicle_id), "vehicle_lpaeq_dba": np.asarray(m.vehicle_lpaeq_dba, float).tolist(),
            **{name: getattr(m, name) for name in SQUEAL_MEASURES}}


def noise_residual_fields(r: Residual, frame_id: str) -> Fields:
    out = {f.name: getattr(r, f.name) for f in dataclass_fields(r) if f.name != "stamp_ns"}
    out.update(header=header_fields(r.stamp_ns, frame_id), band_centre_hz=r.band_centre_hz.tolist(),
               residual_db=r.residual_db.tolist(), vehicle_id=list(r.vehicle_id))
    return out


# -- back to records ------------------------------------------------------------------------------
def measurement_from_msg(msg: Any) -> Measurement:
    """A MeasuredPassNoise as a Measurement (its checks are measurement_refusal's)."""
    # A bag recorded before the squeal measures (0.23 and earlier) has none: not measured.
    squeal = {name: type(default)(getattr(msg, name, default)) for name, default in SQUEAL_MEASURES.items()}
    return Measurement(time_ns(msg.header.stamp), str(msg.train_id), float(msg.receiver_distance_m),
                       float(msg.receiver_height_m), int(msg.instrument_class), np.array(msg.band_centre_hz, float),
                       np.array(msg.leq_db, float), float(msg.lpaeq_tp_dba), float(msg.lpafmax_dba),
                       float(msg.tel_dba), bool(msg.squeal_detected), tuple(str(v) for v in msg.vehicle_id),
                       np.array(msg.vehicle_lpaeq_dba, float), **squeal)


def residual_from_msg(msg: Any) -> Residual:
    """A NoiseResidual as a Residual."""
    names = [f.name for f in dataclass_fields(Residual) if f.name != "stamp_ns"]
    values = {n: getattr(msg, n) for n in names}
    values.update(band_centre_hz=np.array(msg.band_centre_hz, float), residual_db=np.array(msg.residual_db, float),
                  vehicle_id=tuple(msg.vehicle_id))
    return Residual(stamp_ns=time_ns(msg.header.stamp), **values)


def alert_from_msg(msg: Any) -> Alert:
    """A WaysideAlert as an Alert."""
    return Alert(msg.kind, msg.key, msg.severity, msg.active, msg.summary, msg.value, msg.threshold, msg.unit,
                 time_ns(msg.header.stamp), time_ns(msg.raised_time), time_ns(msg.due_time))
