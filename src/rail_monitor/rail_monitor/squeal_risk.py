"""Squeal risk at a site: the site's squeal parameters and the prediction for each train pass.

Glue between the pass table and :mod:`rail_monitor.models.squeal`, shared by the
``squeal_risk_model`` node, batch mode and ``rail-monitor predict squeal``. Per pass:
V0 = speed, Vc = V0 sin(angle of attack), W = the pass's wheel load (or its class's nominal
load); the contact is the class's wheel (rolling radius = diameter / 2, transverse radius
the site's ``contact.wheel_transverse_radius_m``) on a straight rail of head radius
``contact.rail_head_radius_m`` (rail_monitor.site.CONTACT_SPECS); the creep
curve is the friction state's. One dominant wheel mode per site (modal mass, damping,
stiffness at the contact, lateral).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from rail_monitor.errors import ConfigError
from rail_monitor.models import hertz, squeal
from rail_monitor.params import ParamSpec, ParamValues, resolve, section
from rail_monitor.passes import FRICTION_MODIFIER, FRICTION_NAMES, PassTable
from rail_monitor.site import Site

# SquealPrediction.RISK_* values.
RISK_NONE, RISK_LOW, RISK_MEDIUM, RISK_HIGH = range(4)

# Creep curves per friction state (k1 = friction peak, k2 = sliding slope per unit xi').
# Dry: the seed's rig values (k1 = 0.27, k2 = -0.02, section 3.3) rounded to a rail steel
# peak of 0.3; wet: lower peak, milder fall; friction modifier: mu about 0.35 with a positive
# slope (seed section 2.1, ref. [12]); contaminated (leaf film): low adhesion. Site-tunable.
CREEP_DEFAULTS: dict[str, tuple[float, float]] = {
    "dry": (0.30, -0.02),
    "wet": (0.20, -0.008),
    "friction_modifier": (0.35, 0.01),
    "contaminated": (0.10, -0.01),
}

SQUEAL_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("modal_mass_kg", 40.0, "Modal mass of the squealing wheel mode at the contact, lateral [kg].",
              0.01, 1.0e4),
    ParamSpec("modal_damping_nspm", 60.0, "Modal damping c of the mode [N s/m] (60: damping ratio 1e-4, an "
              "undamped wheel).", 0.0, 1.0e6),
    ParamSpec("modal_stiffness_npm", 2.27e9, "Modal stiffness k of the mode [N/m] (with 40 kg: 1.2 kHz).",
              1.0, 1.0e13),
    ParamSpec("k3_convention", "kalker_unit", "How k3 follows from Kalker's C22 (models.squeal."
              "lateral_creep_stiffness).", choices=squeal.K3_CONVENTIONS),
    ParamSpec("k3_n", 0.0, "Lateral creep stiffness k3 given directly [N]; 0: from contact mechanics.", 0.0, 1.0e12),
    *(
        spec
        for state, (k1, k2) in CREEP_DEFAULTS.items()
        for spec in (
            ParamSpec(f"creep.{state}.k1", k1, f"Friction peak k1 of the {state} creep curve [-].", 0.01, 1.5),
            ParamSpec(f"creep.{state}.k2", k2, f"Sliding-branch slope k2 of the {state} creep curve, per unit "
                      "normalised creepage [-] (< 0 falling).", -0.5, 0.5),
        )
    ),
    ParamSpec("receiver_distance_m", 7.5, "Distance from the wheel to the receiver [m].", 0.05, 1000.0),
    ParamSpec("radiating_area_m2", 0.9, "Radiating area of the wheel (both sides) [m2].", 0.001, 10.0),
    ParamSpec("radiation_efficiency", 1.0, "Radiation efficiency of the squealing mode [-].", 0.0, 2.0),
    ParamSpec("spatial_average", 0.5, "Surface-averaged over contact-point squared velocity [-].", 0.0, 1.0),
    ParamSpec("reference_amplitude_mps", 1.0, "A w_ref of the relative level 20 lg(A w / A w_ref) [m/s].",
              1.0e-6, 100.0),
    ParamSpec("background_level_dba", 80.0, "Other noise of a pass at the receiver (rolling noise), against "
              "which a friction modifier's benefit is judged [dB(A)].", 0.0, 200.0),
    ParamSpec("risk_medium_dba", 85.0, "Squeal level from which the risk is medium [dB(A)].", 0.0, 200.0),
    ParamSpec("risk_high_dba", 95.0, "Squeal level from which the risk is high [dB(A)].", 0.0, 200.0),
)


@dataclass(frozen=True)
class SquealConfig(ParamValues):
    """The site's squeal parameters (names and units as in SQUEAL_SPECS)."""

    def creep(self, friction_state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """k1, k2 [-] per pass for TrainPass.FRICTION_* values."""
        k1 = np.full(friction_state.shape, np.nan)
        k2 = np.full(friction_state.shape, np.nan)
        for code, name in FRICTION_NAMES.items():
            sel = friction_state == code
            k1[sel], k2[sel] = self[f"creep.{name}.k1"], self[f"creep.{name}.k2"]
        return k1, k2


def squeal_config(values: Mapping[str, Any], prefix: str = "squeal.") -> SquealConfig:
    """Checked squeal parameters from flat parameter values (keys under prefix)."""
    values = resolve(SQUEAL_SPECS, section(values, prefix), where=prefix, strict=True)
    if values["risk_high_dba"] < values["risk_medium_dba"]:
        raise ConfigError(f"parameter '{prefix}risk_high_dba' must not be below '{prefix}risk_medium_dba'")
    return SquealConfig(values)


def _levels(cfg: SquealConfig, amplitude: np.ndarray, frequency: np.ndarray) -> squeal.RadiatedLevel:
    return squeal.radiated_level(
        amplitude, frequency, radiating_area=cfg["radiating_area_m2"],
        radiation_efficiency=cfg["radiation_efficiency"], spatial_average=cfg["spatial_average"],
        distance=cfg["receiver_distance_m"])


def _with_background(level_dba: np.ndarray, background_dba: float) -> np.ndarray:
    """Energy sum of a squeal level (-inf: none) and the background [dB(A)]."""
    return 10.0 * np.log10(10.0 ** (level_dba / 10.0) + 10.0 ** (background_dba / 10.0))


def predict(cfg: SquealConfig, site: Site, passes: PassTable) -> dict[str, np.ndarray]:
    """SquealPrediction fields per pass (arrays, units as in the message), vectorised.

    ``passes`` must be valid for the site with class defaults filled
    (:func:`rail_monitor.passes.with_class_defaults`).
    """
    v0 = passes.speed_mps
    vc = v0 * np.sin(np.abs(passes.angle_of_attack_rad))
    load = passes.wheel_load_n
    k1, k2 = cfg.creep(passes.friction_state)
    wheel_radius = np.array([site.vehicle(c).wheel_diameter_m / 2.0 for c in passes.vehicle_class])
    kalker_force = _kalker_lateral_force(cfg, site, wheel_radius, load)
    k3 = _k3(cfg, kalker_force, k1)
    mass, damping, stiffness = cfg["modal_mass_kg"], cfg["modal_damping_nspm"], cfg["modal_stiffness_npm"]
    lc = squeal.limit_cycle_amplitude(v0, vc, load, damping, k1, k2, k3)
    freq = np.broadcast_to(squeal.squeal_frequency(mass, stiffness), v0.shape)
    lev = _levels(cfg, lc.amplitude, freq)

    # The same passes with the friction-modifier curve: the benefit against the background.
    fm_k1, fm_k2 = cfg.creep(np.full_like(passes.friction_state, FRICTION_MODIFIER))
    fm = squeal.limit_cycle_amplitude(v0, vc, load, damping, fm_k1, fm_k2, _k3(cfg, kalker_force, fm_k1))
    fm_lev = _levels(cfg, fm.amplitude, freq)
    bg = cfg["background_level_dba"]
    benefit = _with_background(lev.level_dba, bg) - _with_background(fm_lev.level_dba, bg)

    risk = np.where(~lc.unstable, RISK_NONE,
                    np.where(lev.level_dba >= cfg["risk_high_dba"], RISK_HIGH,
                             np.where(lev.level_dba >= cfg["risk_medium_dba"], RISK_MEDIUM, RISK_LOW)))
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
        "relative_level_db": squeal.relative_level(lc.amplitude, cfg["reference_amplitude_mps"]),
        "friction_modifier_benefit_db": benefit,
        "risk": risk.astype(np.int8),
    }


def _kalker_lateral_force(cfg: SquealConfig, site: Site, wheel_radius_m: np.ndarray,
                          load_n: np.ndarray) -> np.ndarray | None:
    """G a b C22 [N] of the site's wheel-rail contact (None when k3 is given directly)."""
    if cfg["k3_n"] > 0.0:
        return None
    c = site.contact
    return squeal.kalker_lateral_stiffness(site.contact_patch(wheel_radius_m, load_n), c.young_modulus_pa,
                                           c.poisson_ratio)


def _k3(cfg: SquealConfig, kalker_force: np.ndarray | None, mu0: np.ndarray) -> np.ndarray:
    """k3 [N] per pass: given directly, or from G a b C22 under the configured convention."""
    if kalker_force is None:
        return np.full(mu0.shape, cfg["k3_n"])
    return squeal.lateral_creep_stiffness(kalker_force, mu0, cfg["k3_convention"])


@dataclass(frozen=True)
class SquealCase:
    """Physical inputs of one squeal calculation (SI units, as in models.squeal)."""

    speed_mps: float
    load_n: float
    mass_kg: float
    damping_nspm: float
    stiffness_npm: float
    k1: float
    k2: float
    k3_n: float


# Seed Figure 5 (two-disc rig): radii of the lower wheel (rolling, transverse) and the upper
# wheel [m], E [Pa], nu, W [N], m [kg], c [N s/m], k [N/m]; V0 = 17.8 m/s (800 rpm) and the
# creep curve k1 = 0.27, k2 = -0.02 of section 3.3.
RIG_RADII_M = (0.213, 0.300, 0.085, 0.040)
RIG = {"young_modulus_pa": 175e9, "poisson_ratio": 0.28, "load_n": 1000.0, "mass_kg": 3.1, "damping_nspm": 42.0,
       "stiffness_npm": 1.6e8, "speed_mps": 17.8, "k1": 0.27, "k2": -0.02}


def rig_case(convention: str = "kalker_unit") -> SquealCase:
    """The seed's rig (Figure 5) with k3 from its Hertz contact and Kalker's C22 (convention)."""
    e, nu = RIG["young_modulus_pa"], RIG["poisson_ratio"]
    contact = hertz.contact_ellipse(*RIG_RADII_M, hertz.contact_modulus(e, nu), RIG["load_n"])
    k3 = float(squeal.lateral_creep_stiffness(squeal.kalker_lateral_stiffness(contact, e, nu), RIG["k1"], convention))
    return SquealCase(RIG["speed_mps"], RIG["load_n"], RIG["mass_kg"], RIG["damping_nspm"], RIG["stiffness_npm"],
                      RIG["k1"], RIG["k2"], k3)


def site_case(cfg: SquealConfig, site: Site, vehicle_class: str, friction_state: int, speed_mps: float,
              load_n: float = 0.0) -> SquealCase:
    """The site's wheel mode, contact and creep curve for one vehicle class and friction state."""
    vehicle = site.vehicle(vehicle_class)
    load = load_n or vehicle.wheel_load_n
    k1, k2 = (float(x[0]) for x in cfg.creep(np.array([friction_state])))
    kalker_force = _kalker_lateral_force(cfg, site, np.array([vehicle.wheel_diameter_m / 2.0]), np.array([load]))
    k3 = float(_k3(cfg, kalker_force, np.array([k1]))[0])
    return SquealCase(speed_mps, load, cfg["modal_mass_kg"], cfg["modal_damping_nspm"], cfg["modal_stiffness_npm"],
                      k1, k2, k3)


def sweep(case: SquealCase, crabbing_mps: np.ndarray, reference_mps: float | None = None,
          ode: bool = False) -> dict[str, np.ndarray]:
    """Amplitude, regime and relative level over crabbing velocities [m/s] for one case.

    The relative level is 20 lg(A w / A w_ref), A w_ref = reference_mps or the largest
    amplitude of the sweep. With ``ode``, each row also gets the time-domain amplitude.
    """
    vc = np.asarray(crabbing_mps, float)
    lc = squeal.limit_cycle_amplitude(case.speed_mps, vc, case.load_n, case.damping_nspm, case.k1, case.k2, case.k3_n)
    ref = reference_mps or (float(np.max(lc.amplitude)) if np.any(lc.amplitude > 0) else 1.0)
    out = {
        "crabbing_velocity_mps": vc,
        "angle_of_attack_mrad": 1e3 * np.arcsin(np.clip(vc / case.speed_mps, -1.0, 1.0)),
        "velocity_amplitude_mps": lc.amplitude,
        "regime": lc.regime,
        "relative_level_db": squeal.relative_level(lc.amplitude, ref),
        "critical_slip_velocity_mps": np.broadcast_to(lc.critical_slip, vc.shape),
        "effective_damping_nspm": np.broadcast_to(lc.effective_damping, vc.shape),
    }
    if ode:
        out["ode_amplitude_mps"] = np.array([
            squeal.simulate_limit_cycle(case.speed_mps, float(v), case.load_n, case.mass_kg, case.damping_nspm,
                                        case.stiffness_npm, case.k1, case.k2, case.k3_n).amplitude for v in vc])
    return out
