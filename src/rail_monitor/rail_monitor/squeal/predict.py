"""Squeal at a site: the prediction for each train pass.

Glue between the pass table and :mod:`rail_monitor.models.squeal`, shared by the
``squeal_risk_model`` node, batch mode and ``rail-monitor predict squeal``. Per pass:
V0 = speed, Vc = V0 sin(angle of attack), W = the pass's wheel load (or its class's nominal
load); the contact is the class's wheel (rolling radius = diameter / 2, transverse radius
the site's ``contact.wheel_transverse_radius_m``) on a straight rail of head radius
``contact.rail_head_radius_m`` (:data:`rail_monitor.core.site.CONTACT_SPECS`); the creep
curve is the friction state's. One dominant wheel mode per site (modal mass, damping,
stiffness at the contact, lateral).
"""

from __future__ import annotations

import numpy as np

from rail_monitor.core.passes import FRICTION_MODIFIER, PassTable
from rail_monitor.core.site import Site
from rail_monitor.models import squeal
from rail_monitor.squeal.config import RISK_HIGH, RISK_LOW, RISK_MEDIUM, RISK_NONE, SquealConfig


def _levels(cfg: SquealConfig, amplitude: np.ndarray, frequency: np.ndarray) -> squeal.RadiatedLevel:
    return squeal.radiated_level(
        amplitude, frequency, radiating_area=cfg.radiating_area_m2,
        radiation_efficiency=cfg.radiation_efficiency, spatial_average=cfg.spatial_average,
        distance=cfg.receiver_distance_m)


def _with_background(level_dba: np.ndarray, background_dba: float) -> np.ndarray:
    """Energy sum of a squeal level (-inf: none) and the background [dB(A)]."""
    return 10.0 * np.log10(10.0 ** (level_dba / 10.0) + 10.0 ** (background_dba / 10.0))


def predict(cfg: SquealConfig, site: Site, passes: PassTable) -> dict[str, np.ndarray]:
    """SquealPrediction fields per pass (arrays, units as in the message), vectorised.

    ``passes`` must be valid for the site with class defaults filled
    (:func:`rail_monitor.core.passes.with_class_defaults`).
    """
    v0 = passes.speed_mps
    vc = v0 * np.sin(np.abs(passes.angle_of_attack_rad))
    load = passes.wheel_load_n
    k1, k2 = cfg.creep(passes.friction_state)
    wheel_radius = np.array([site.vehicle(c).wheel_diameter_m / 2.0 for c in passes.vehicle_class])
    kalker_force = kalker_lateral_force(cfg, site, wheel_radius, load)
    k3 = creep_stiffness(cfg, kalker_force, k1)
    mass, damping, stiffness = cfg.modal_mass_kg, cfg.modal_damping_nspm, cfg.modal_stiffness_npm
    lc = squeal.limit_cycle_amplitude(v0, vc, load, damping, k1, k2, k3)
    freq = np.broadcast_to(squeal.squeal_frequency(mass, stiffness), v0.shape)
    lev, risk = level_and_risk(cfg, lc.amplitude, lc.unstable, freq)

    # The same passes with the friction-modifier curve: the benefit against the background.
    fm_k1, fm_k2 = cfg.creep(np.full_like(passes.friction_state, FRICTION_MODIFIER))
    fm = squeal.limit_cycle_amplitude(v0, vc, load, damping, fm_k1, fm_k2, creep_stiffness(cfg, kalker_force, fm_k1))
    fm_lev = _levels(cfg, fm.amplitude, freq)
    bg = cfg.background_level_dba
    benefit = _with_background(lev.level_dba, bg) - _with_background(fm_lev.level_dba, bg)

    return {
        "friction_state": passes.friction_state,
        "speed_mps": v0,
        "crabbing_velocity_mps": vc,
        "critical_slip_velocity_mps": lc.critical_slip,
        "effective_damping_nspm": lc.effective_damping,
        "unstable": lc.unstable,
        "regime": lc.regime,
        "velocity_amplitude_mps": lc.amplitude,
        "frequency_hz": freq,
        "level_db": lev.level_db,
        "level_dba": lev.level_dba,
        "relative_level_db": squeal.relative_level(lc.amplitude, cfg.reference_amplitude_mps),
        "friction_modifier_benefit_db": benefit,
        "risk": risk,
    }


def level_and_risk(cfg: SquealConfig, amplitude: np.ndarray, unstable: np.ndarray,
                   frequency: np.ndarray) -> tuple[squeal.RadiatedLevel, np.ndarray]:
    """The radiated level at the site's receiver of a wheel velocity amplitude [m/s] at a squeal
    frequency [Hz], and the risk class (RISK_*, int8) from the site's dB(A) limits."""
    lev = _levels(cfg, amplitude, frequency)
    risk = np.where(~unstable, RISK_NONE,
                    np.where(lev.level_dba >= cfg.risk_high_dba, RISK_HIGH,
                             np.where(lev.level_dba >= cfg.risk_medium_dba, RISK_MEDIUM, RISK_LOW)))
    return lev, risk.astype(np.int8)


def kalker_lateral_force(cfg: SquealConfig, site: Site, wheel_radius_m: np.ndarray,
                          load_n: np.ndarray) -> np.ndarray | None:
    """G a b C22 [N] of the site's wheel-rail contact (None when k3 is given directly)."""
    if cfg.k3_n > 0.0:
        return None
    c = site.contact
    return squeal.kalker_lateral_stiffness(site.contact_patch(wheel_radius_m, load_n), c.young_modulus_pa,
                                           c.poisson_ratio)


def creep_stiffness(cfg: SquealConfig, kalker_force: np.ndarray | None, mu0: np.ndarray) -> np.ndarray:
    """k3 [N] per pass: given directly, or from G a b C22 under the configured convention."""
    if kalker_force is None:
        return np.full(mu0.shape, cfg.k3_n)
    return squeal.lateral_creep_stiffness(kalker_force, mu0, cfg.k3_convention)
