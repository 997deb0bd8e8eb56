"""Conversions between rail_msgs messages and the pure tables: the one place for each."""

from __future__ import annotations

from typing import Any

from builtin_interfaces.msg import Time

from rail_monitor.timeutil import from_sec_nanosec, to_sec_nanosec
from rail_msgs.msg import SquealPrediction, TrainPass


def time_msg(ns: int) -> Time:
    sec, nanosec = to_sec_nanosec(ns)
    return Time(sec=sec, nanosec=nanosec)


def time_ns(t: Time) -> int:
    return from_sec_nanosec(t.sec, t.nanosec)


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
