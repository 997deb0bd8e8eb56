"""What a predicted pass sounds like: the rolling noise of a train of one class at one speed (and its
squeal, where the squeal model finds the pass unstable), as the receiver would record it
(``rail-monitor predict passby-audio``; models.auralisation)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.passes import FRICTION_BY_NAME, MAX_SPEED_MPS, synthetic_passes
from rail_monitor.engine.site_config import SiteConfig
from rail_monitor.models.auralisation import passby_pressure
from rail_monitor.noise.predict import RollingNoiseModel
from rail_monitor.squeal.predict import predict as predict_squeal


@dataclass(frozen=True)
class PassAudio:
    pressure_pa: np.ndarray     # the receiver's pressure [Pa]
    fs_hz: float
    pass_start_s: float         # the train's front at the receiver's perpendicular [s from the start]
    pass_time_s: float          # Tp [s]
    band_centre_hz: np.ndarray  # [Hz]
    lp_db: np.ndarray           # the predicted LpZeq,Tp per band [dB re 20 uPa]
    lpaeq_tp_dba: float         # the predicted levels of the rolling noise alone (line source) [dB(A)]
    lpafmax_dba: float
    tel_dba: float
    squeal_hz: float            # NaN: no squeal predicted (or not asked)
    squeal_db: float            # at the receiver's distance [dB re 20 uPa]; NaN likewise
    model: str


def pass_audio(values: Mapping[str, Any], vehicle_class: str | None = None, speed_mps: float | None = None,
               vehicles: int | None = None, friction: str = "dry", aoa_mrad: float = 0.0, model: str | None = None,
               squeal: bool = True, fs_hz: float = 48_000.0, margin_s: float = 5.0, seed: int = 0) -> PassAudio:
    """The audio of one predicted pass of the site of the flat values: the class (default its first)
    at speed_mps (default its mean), vehicles (default its mean consist), on a friction state at an
    angle of attack [mrad] (for the squeal), by the noise model (default the site's first). The
    rolling noise's pass-by levels are predicted with the line source the audio is made of."""
    config = SiteConfig.from_values(values)
    site = config.site
    cls = site.vehicle(vehicle_class or next(iter(site.vehicles)))
    v = float(speed_mps or cls.speed_mean_mps)
    if not 0.0 < v <= MAX_SPEED_MPS:
        raise RailMonitorError(f"--speed must be in (0, {MAX_SPEED_MPS:g}] m/s")
    if friction not in FRICTION_BY_NAME:
        raise RailMonitorError(f"unknown friction state {friction!r} (use {', '.join(FRICTION_BY_NAME)})")
    noise = RollingNoiseModel(site, dataclasses.replace(config.noise, pass_by_sources="line"))
    table = synthetic_passes(site, cls, np.array([v]), vehicles or round(cls.mean_vehicles))
    table.friction_state[:] = FRICTION_BY_NAME[friction]
    table.angle_of_attack_rad[:] = 1e-3 * aoa_mrad
    pred = noise.predict(table, model)
    (_, psi), _ = noise.receiver.paths()
    d = noise.receiver.distance_m
    tone = None
    if squeal:
        sq = predict_squeal(config.squeal, site, table)
        if bool(sq["unstable"][0]):  # its level at the squeal model's distance, brought to the receiver's
            spread = 20.0 * np.log10(config.squeal.receiver_distance_m / d)
            tone = (float(sq["frequency_hz"][0]), float(sq["level_db"][0]) + spread)
    length = float(table.train_length_m[0])
    p = passby_pressure(noise.band, pred.lp_db[0], d, d / np.cos(psi), length, v, fs_hz, margin_s, margin_s, tone,
                        seed)
    return PassAudio(p, fs_hz, margin_s, length / v, pred.band_centre_hz, pred.lp_db[0],
                     float(pred.lpaeq_tp_dba[0]), float(pred.lpafmax_dba[0]), float(pred.tel_dba[0]),
                     tone[0] if tone else float("nan"), tone[1] if tone else float("nan"), pred.model)
