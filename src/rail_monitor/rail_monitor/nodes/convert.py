"""Conversions between rail_msgs messages and the pure tables: the one place for each."""

from __future__ import annotations

from typing import Any

from builtin_interfaces.msg import Time

from rail_monitor.timeutil import from_sec_nanosec, to_sec_nanosec
from rail_msgs.msg import TrainPass


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

