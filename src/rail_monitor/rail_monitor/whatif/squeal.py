"""What-if squeal: one case (the paper's two-disc rig or a site's class and friction state) over
crabbing velocities, as ``rail-monitor predict squeal`` reports it (callable from Python too)."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from rail_monitor.core.contact import creep_stiffness
from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.passes import FRICTION_BY_NAME, PassTable
from rail_monitor.core.site import Site, site_from_values
from rail_monitor.models import hertz, squeal, squeal_ode, squeal_radiation
from rail_monitor.squeal.config import SquealConfig, squeal_config
from rail_monitor.squeal.predict import WheelMode, level_and_risk, wheel_mode


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
    radiating_area_m2: float = 0.9      # of the wheel, both sides
    radiation_efficiency: float = 1.0


# The paper's Figure 5 (two-disc rig): radii of the lower wheel (rolling, transverse) and the upper
# wheel [m], E [Pa], nu, W [N], m [kg], c [N s/m], k [N/m]; V0 = 17.8 m/s (800 rpm) and the
# creep curve k1 = 0.27, k2 = -0.02 of section 3.3.
RIG_RADII_M = (0.213, 0.300, 0.085, 0.040)
RIG = {"young_modulus_pa": 175e9, "poisson_ratio": 0.28, "load_n": 1000.0, "mass_kg": 3.1, "damping_nspm": 42.0,
       "stiffness_npm": 1.6e8, "speed_mps": 17.8, "k1": 0.27, "k2": -0.02}


def rig_case(convention: str = "reduced_kalker") -> SquealCase:
    """The paper's rig (Figure 5) with k3 from its Hertz contact and Kalker's C22 (convention)."""
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
    k1, k2 = site.contact.creep(np.array([friction_state]))
    k3 = float(creep_stiffness(site, site.contact_patch(vehicle.wheel_diameter_m / 2.0, load), k1)[0])
    k1, k2 = float(k1[0]), float(k2[0])
    mode = wheel_mode(site, np.array([vehicle_class], object))
    return SquealCase(speed_mps, load, float(mode.mass_kg[0]), float(mode.damping_nspm[0]),
                      float(mode.stiffness_npm[0]), k1, k2, k3, float(mode.area_m2[0]), float(mode.efficiency[0]))


def sweep(case: SquealCase, crabbing_mps: np.ndarray, reference_mps: float | None = None,
          ode: bool = False, cfg: SquealConfig | None = None) -> dict[str, np.ndarray]:
    """Amplitude, regime and relative level over crabbing velocities [m/s] for one case.

    The relative level is 20 lg(A w / A w_ref), A w_ref = reference_mps or the largest
    amplitude of the sweep. With ``ode``, each row also gets the time-domain amplitude. With a
    site's cfg, each row also gets the level at the site's receiver [dB, dB(A)] and the risk class,
    as the squeal node computes them (at the case's mode frequency sqrt(k/m)/2 pi).
    """
    vc = np.asarray(crabbing_mps, float)
    lc = squeal.limit_cycle_amplitude(case.speed_mps, vc, case.load_n, case.damping_nspm, case.k1, case.k2, case.k3_n)
    ref = reference_mps or (float(np.max(lc.amplitude)) if np.any(lc.amplitude > 0) else 1.0)
    out = {
        "crabbing_velocity_mps": vc,
        "angle_of_attack_mrad": 1e3 * np.arcsin(np.clip(vc / case.speed_mps, -1.0, 1.0)),
        "velocity_amplitude_mps": lc.amplitude,
        "regime": lc.regime,
        "relative_level_db": squeal_radiation.relative_level(lc.amplitude, ref),
        "critical_slip_velocity_mps": np.broadcast_to(lc.critical_slip, vc.shape),
        "effective_damping_nspm": np.broadcast_to(lc.effective_damping, vc.shape),
    }
    if cfg is not None:
        freq = np.broadcast_to(squeal_radiation.squeal_frequency(case.mass_kg, case.stiffness_npm), vc.shape)
        mode = WheelMode(freq, np.full(vc.shape, case.mass_kg), np.full(vc.shape, case.damping_nspm),
                         np.full(vc.shape, case.radiating_area_m2), np.full(vc.shape, case.radiation_efficiency))
        lev, out["risk"] = level_and_risk(cfg, mode, lc.amplitude, lc.unstable)
        out["level_db"], out["level_dba"], out["frequency_hz"] = lev.level_db, lev.level_dba, freq
    if ode:
        out["ode_amplitude_mps"] = np.array([
            squeal_ode.simulate_limit_cycle(case.speed_mps, float(v), case.load_n, case.mass_kg, case.damping_nspm,
                                        case.stiffness_npm, case.k1, case.k2, case.k3_n).amplitude for v in vc])
    return out


def squeal_case(values: Mapping[str, Any] | None, vehicle_class: str | None = None, friction: str = "dry",
                speed_mps: float | None = None, load_n: float | None = None, k3_convention: str | None = None,
                **overrides: float) -> tuple[SquealCase, str]:
    """The case to evaluate and a line saying what it is: the paper's rig when values is None,
    else the site of the flat parameter values for a vehicle class (default: its first) and a
    friction state at a speed [m/s] (default: the class's mean) and wheel load [N] (default: its
    nominal). overrides: SquealCase fields set directly (e.g. k3_n)."""
    if values is None:
        if load_n:
            raise RailMonitorError("--load does not apply to --rig: the rig's k3 is for its 1000 N (Figure 5)")
        case, where = rig_case(k3_convention or "reduced_kalker"), "the paper's rig (Figure 5)"
    else:
        values = dict(values)
        if k3_convention:
            values["contact.k3_convention"] = k3_convention
        site = site_from_values(values)
        cls = vehicle_class or next(iter(site.vehicles))
        case = site_case(squeal_config(values), site, cls, FRICTION_BY_NAME[friction],
                         speed_mps or site.vehicle(cls).speed_mean_mps, load_n or 0.0)
        where = f"site {site.site_id}, class {cls}, {friction}"
    if speed_mps:
        overrides["speed_mps"] = speed_mps
    return dataclasses.replace(case, **overrides), where


def crabbing_velocities(case: SquealCase, sweep_range: tuple[float, float, float] | None = None,
                        crabbing_mps: float | None = None, aoa_mrad: float | None = None) -> np.ndarray:
    """The crabbing velocities [m/s] to evaluate: a sweep (start, stop, count), one value, or the
    one of an angle of attack [mrad] at the case's speed (default 10 mrad)."""
    if sweep_range:
        start, stop, count = sweep_range
        return np.linspace(start, stop, int(count))
    if crabbing_mps is not None:
        return np.array([crabbing_mps])
    return np.array([case.speed_mps * np.sin(1e-3 * (aoa_mrad if aoa_mrad is not None else 10.0))])


def friction_states(values: Mapping[str, Any], passes: PassTable) -> list[dict[str, Any]]:
    """Per friction state of the valid passes of a history: its creep curve, how many passes, the
    share unstable, the median onset angle of attack [mrad] (arcsin of the saturation creepage),
    the mean level of the unstable ones [dB(A)], and the friction modifier's cut of the squealing
    passes' energy-mean level with the background [dB(A)] (NaN where none squeals)."""
    from rail_monitor.core.contact import contact_state
    from rail_monitor.core.passes import FRICTION_NAMES, accepted_passes
    from rail_monitor.squeal.predict import predict

    site, cfg = site_from_values(values), squeal_config(values)
    table = accepted_passes(passes, site)
    out, cs = predict(cfg, site, table), contact_state(site, table)
    bg = 10.0 ** (cfg.background_level_dba / 10.0)
    rows = []
    for code, name in FRICTION_NAMES.items():
        sel = table.friction_state == code
        if not sel.any():
            continue
        sq = sel & out["unstable"]
        with np.errstate(divide="ignore"):
            before = 10.0 ** (out["level_dba"][sq] / 10.0) + bg
        after = before / 10.0 ** (out["friction_modifier_benefit_db"][sq] / 10.0)
        k1, k2 = (float(x[0]) for x in site.contact.creep(np.array([code])))
        rows.append({"friction_state": name, "k1": k1, "k2": k2, "passes": int(sel.sum()),
                     "unstable_share": float(out["unstable"][sel].mean()),
                     "onset_mrad": float(1e3 * np.median(np.arcsin(np.clip(cs.saturation_creepage[sel], 0, 1)))),
                     "mean_level_dba": float(np.mean(out["level_dba"][sq])) if sq.any() else float("nan"),
                     "friction_modifier_cut_dba": float(10.0 * np.log10(before.mean() / after.mean()))
                     if sq.any() and code != FRICTION_BY_NAME["friction_modifier"] else float("nan")})
    return rows
