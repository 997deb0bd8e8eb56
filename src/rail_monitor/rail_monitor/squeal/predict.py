"""Squeal at a site: the prediction for each train pass.

Glue between the pass table and :mod:`rail_monitor.models.squeal`, shared by the
``squeal_risk_model`` node, batch mode and ``rail-monitor predict squeal``. Per pass:
V0 = speed; Vc, W, the creep curve and k3 are the pass's contact state
(:mod:`rail_monitor.core.contact`: the class's wheel on the rail head, the friction state's
curve). The squealing wheel mode (frequency, modal mass, damping, radiation) is the pass's
vehicle class's.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from rail_monitor.core.contact import ContactState, contact_state
from rail_monitor.core.passes import FRICTION_MODIFIER, PassTable
from rail_monitor.core.site import Site
from rail_monitor.models import squeal, squeal_radiation
from rail_monitor.squeal.config import RISK_HIGH, RISK_LOW, RISK_MEDIUM, RISK_NONE, SquealConfig


class WheelMode(NamedTuple):
    """The squealing mode of each pass's class (arrays per pass): frequency [Hz], modal mass [kg],
    viscous damping c = 2 zeta m omega [N s/m], radiating area [m2] and radiation efficiency [-]."""

    frequency_hz: np.ndarray
    mass_kg: np.ndarray
    damping_nspm: np.ndarray
    area_m2: np.ndarray
    efficiency: np.ndarray

    @property
    def stiffness_npm(self) -> np.ndarray:
        return self.mass_kg * (2.0 * np.pi * self.frequency_hz) ** 2


def wheel_mode(site: Site, vehicle_class: np.ndarray) -> WheelMode:
    """The vehicle classes' squealing modes (VEHICLE_SPECS squeal_*), one row per pass."""
    col = {k: site.per_pass(vehicle_class, k).astype(np.float64) for k in (
        "squeal_mode_hz", "squeal_modal_mass_kg", "squeal_damping_ratio", "wheel_radiating_area_m2",
        "squeal_radiation_efficiency")}
    f, m = col["squeal_mode_hz"], col["squeal_modal_mass_kg"]
    return WheelMode(f, m, 2.0 * col["squeal_damping_ratio"] * m * 2.0 * np.pi * f, col["wheel_radiating_area_m2"],
                     col["squeal_radiation_efficiency"])


def _levels(cfg: SquealConfig, mode: WheelMode, amplitude: np.ndarray) -> squeal_radiation.RadiatedLevel:
    return squeal_radiation.radiated_level(
        amplitude, mode.frequency_hz, radiating_area=mode.area_m2, radiation_efficiency=mode.efficiency,
        spatial_average=cfg.spatial_average, distance=cfg.receiver_distance_m)


def _with_background(level_dba: np.ndarray, background_dba: float) -> np.ndarray:
    """Energy sum of a squeal level (-inf: none) and the background [dB(A)]."""
    return 10.0 * np.log10(10.0 ** (level_dba / 10.0) + 10.0 ** (background_dba / 10.0))


def predict(cfg: SquealConfig, site: Site, passes: PassTable) -> dict[str, np.ndarray]:
    """SquealPrediction fields per pass (arrays, units as in the message), vectorised.

    ``passes`` must be valid for the site with class defaults filled
    (:func:`rail_monitor.core.passes.with_class_defaults`). The creep curve, k3 and Vc are the
    pass's contact state (:func:`rail_monitor.core.contact.contact_state`).
    """
    v0 = passes.speed_mps
    cs = contact_state(site, passes)
    mode = wheel_mode(site, passes.vehicle_class)
    lc = _limit_cycle(mode, v0, cs)
    lev, risk = level_and_risk(cfg, mode, lc.amplitude, lc.unstable)
    return {
        "friction_state": passes.friction_state,
        "speed_mps": v0,
        "crabbing_velocity_mps": cs.crabbing_mps,
        "critical_slip_velocity_mps": lc.critical_slip,
        "effective_damping_nspm": lc.effective_damping,
        "unstable": lc.unstable,
        "regime": lc.regime,
        "velocity_amplitude_mps": lc.amplitude,
        "frequency_hz": mode.frequency_hz,
        "level_db": lev.level_db,
        "level_dba": lev.level_dba,
        "relative_level_db": squeal_radiation.relative_level(lc.amplitude, cfg.reference_amplitude_mps),
        "friction_modifier_benefit_db": friction_modifier_benefit(cfg, site, passes, mode, lev.level_dba, cs),
        "risk": risk,
    }


def risk_at_speeds(cfg: SquealConfig, site: Site, passes: PassTable, speed_mps: np.ndarray) -> np.ndarray:
    """The risk class (RISK_*) of each pass were it run at other speeds [m/s], an array (G, N) or
    broadcasting to it: the pass's contact and wheel mode, computed once, at each speed (the
    advice's what-if; ``passes`` as for :func:`predict`)."""
    cs = contact_state(site, passes)
    mode = wheel_mode(site, passes.vehicle_class)
    lc = _limit_cycle(mode, speed_mps, cs.at_speed(speed_mps))
    return level_and_risk(cfg, mode, lc.amplitude, lc.unstable)[1]


def _limit_cycle(mode: WheelMode, speed: np.ndarray, cs: ContactState) -> squeal.LimitCycle:
    return squeal.limit_cycle_amplitude(speed, cs.crabbing_mps, cs.load_n, mode.damping_nspm, cs.k1, cs.k2, cs.k3_n)


def friction_modifier_benefit(cfg: SquealConfig, site: Site, passes: PassTable, mode: WheelMode,
                              level_dba: np.ndarray, own: ContactState | None = None) -> np.ndarray:
    """What a friction modifier would take off each pass's noise [dB(A)], against the background.

    With the modifier a share e (friction_modifier_effectiveness) of the wheels meets the film
    (the friction-modifier creep curve) and the rest the rail as it is, so the conditioned pass's
    squeal energy is e 10^(L_fm / 10) + (1 - e) 10^(L / 10): at most -10 lg(1 - e) quieter, 13 dB(A)
    at e = 0.95 (Eadie & Santoro, J. Sound Vib. 293 (2006) 747-757, measured 6.3-22.8 dB(A), mean
    12). 0 for a pass already conditioned. own: the passes' contact state, when at hand.
    """
    fm = np.full_like(passes.friction_state, FRICTION_MODIFIER)
    lc = _limit_cycle(mode, passes.speed_mps, contact_state(site, passes, fm, own))
    fm_dba = _levels(cfg, mode, lc.amplitude).level_dba
    e = cfg.friction_modifier_effectiveness
    with np.errstate(divide="ignore"):
        mixed = 10.0 * np.log10(e * 10.0 ** (fm_dba / 10.0) + (1.0 - e) * 10.0 ** (level_dba / 10.0))
    bg = cfg.background_level_dba
    return np.where(passes.friction_state == FRICTION_MODIFIER, 0.0,
                    _with_background(level_dba, bg) - _with_background(mixed, bg))


def level_and_risk(cfg: SquealConfig, mode: WheelMode, amplitude: np.ndarray,
                   unstable: np.ndarray) -> tuple[squeal_radiation.RadiatedLevel, np.ndarray]:
    """The radiated level at the site's receiver of a wheel velocity amplitude [m/s] of a mode,
    and the risk class (RISK_*, int8) from the site's dB(A) limits."""
    lev = _levels(cfg, mode, amplitude)
    risk = np.where(~unstable, RISK_NONE,
                    np.where(lev.level_dba >= cfg.risk_high_dba, RISK_HIGH,
                             np.where(lev.level_dba >= cfg.risk_medium_dba, RISK_MEDIUM, RISK_LOW)))
    return lev, risk.astype(np.int8)
