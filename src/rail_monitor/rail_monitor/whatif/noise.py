"""What-if rolling noise: a train of one class at given speeds, before and after days of
corrugation growth, as ``rail-monitor predict noise`` reports it (callable from Python too)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from rail_monitor.core.errors import RailMonitorError
from rail_monitor.core.passes import FRICTION_BY_NAME, MAX_SPEED_MPS, synthetic_passes
from rail_monitor.core.site import Site, VehicleClass, site_from_values
from rail_monitor.models.passby import METRIC_DEFINITIONS
from rail_monitor.noise.config import noise_config
from rail_monitor.noise.predict import INCREASE_REFERENCE, RollingNoiseModel
from rail_monitor.noise.records import Corrugation, NoisePrediction

# What each spectrum of the JSON holds (bands: band_centre_hz).
SPECTRUM_DEFINITIONS = {
    "components_lpaeq_dba": "LpAeq,Tp of each source component alone [dB(A)] (CNOSSOS-EU's superstructure term "
                            "for freight classes only; components ending _b radiate from source B, 4 m above the "
                            "rail head, the others from source A)",
    "lw0_per_vehicle_db": "sound power per vehicle per component and band [dB re 1 pW]: for CNOSSOS-EU L_W,0 of "
                          "Directive 2015/996 Annex II eqs. 2.3.7-2.3.9 (2.3.14 for a bridge; Table G-5 for "
                          "traction_a/_b, G-6 for aerodynamic_a/_b), no directivity",
    "lw_db_per_m": "sound power per metre of train, all components [dB re 1 pW/m]",
    "lp_db": "LpZeq,Tp per band at the receiver [dB re 20 uPa]",
    "roughness_db": "combined effective roughness at the band frequencies [dB re 1 um]",
}
SINGLE_NUMBERS = ("lpaeq_tp_dba", "lpafmax_dba", "tel_dba", "pass_by_time_s", "roughness_growth_increase_db")


@dataclass
class NoiseWhatIf:
    """A what-if's inputs and results: one prediction per (model, days of growth)."""

    where: str                          # what was predicted, for people
    model: RollingNoiseModel
    vehicle_class: VehicleClass
    vehicles: int
    speeds: np.ndarray                  # [m/s]
    passes_per_day: float               # trains per day of the growth [1/day]
    results: dict[tuple[str, float], NoisePrediction]
    sound_power: dict[tuple[str, float], dict[str, np.ndarray]]  # L_W,0 per vehicle by component [dB re 1 pW]


def growth_states(values: Mapping[str, Any], site: Site, cls: VehicleClass, speed_mps: float,
                  growth_days: Sequence[float], passes_per_day: float) -> dict[float, Corrugation | None]:
    """The corrugation after each number of days of growth from grinding [day] at one speed [m/s] on
    dry rail (key 0: just after grinding); without growth days, {0: None} (the baseline rail)."""
    if not growth_days:
        return {0.0: None}
    from rail_monitor.advice.growth import growth_at_speeds
    from rail_monitor.corrugation.config import corrugation_config
    from rail_monitor.corrugation.estimator import CorrugationEstimator
    from rail_monitor.models.corrugation_state import band_amplitude

    est = CorrugationEstimator(site, corrugation_config(values))
    per_axle = growth_at_speeds(est, np.array([speed_mps]), FRICTION_BY_NAME["dry"])[..., 0]
    axles_per_day = passes_per_day * cls.mean_axles_per_train
    states: dict[float, Corrugation | None] = {0.0: Corrugation(est.bands, est.grinding_amplitude,
                                                                est.grinding_amplitude)}
    for days in growth_days:
        amp = band_amplitude(est.log_components + per_axle * axles_per_day * days)
        states[days] = Corrugation(est.bands, amp, est.grinding_amplitude)
    return states


def predict_noise(values: Mapping[str, Any], vehicle_class: str | None = None, speeds: Sequence[float] | None = None,
                  vehicles: int | None = None, growth_days: Sequence[float] = (),
                  passes_per_day: float = 100.0) -> NoiseWhatIf:
    """Rolling noise of a train of the class (default: the site's first) at the speeds [m/s]
    (default: its mean), on the baseline rail, or after each number of growth days."""
    site = site_from_values(values)
    model = RollingNoiseModel(site, noise_config(values))
    cls = site.vehicle(vehicle_class or next(iter(site.vehicles)))
    v = np.asarray(speeds or [cls.speed_mean_mps], float)
    if np.any(~np.isfinite(v) | (v <= 0) | (v > MAX_SPEED_MPS)):
        raise RailMonitorError(f"--speed values must be in (0, {MAX_SPEED_MPS:g}] m/s")
    n_vehicles = vehicles or round(cls.mean_vehicles)
    table = synthetic_passes(site, cls, v, n_vehicles)
    states = growth_states(values, site, cls, float(v[0]), growth_days, passes_per_day)
    results = {(name, days): model.predict(table, name, state) for name in model.models
               for days, state in states.items()}
    sound_power = {(name, days): model.vehicle_sound_power(table, name, state) for name in model.models
                   for days, state in states.items()}
    where = (f"site {site.site_id}, {cls.name} ({cls.brake_type} brakes, {n_vehicles} vehicles), rail "
             f"{model.cfg.rail_roughness}, {model.track_name}, receiver {model.receiver.distance_m:g} m / "
             f"{model.receiver.height_m:g} m; CNOSSOS-EU edition {model.edition}, {model.cfg.interpolation} rule")
    return NoiseWhatIf(where, model, cls, n_vehicles, v, passes_per_day, results, sound_power)


def summary(r: NoiseWhatIf) -> dict[str, Any]:
    """The what-if as plain data (JSON): per model and growth, per pass its single numbers and spectra."""
    def row(key: tuple[str, float], i: int) -> dict[str, Any]:
        out = r.results[key]
        names, lpaeq = out.components(i)
        return {"speed_mps": float(r.speeds[i]), **{k: float(getattr(out, k)[i]) for k in SINGLE_NUMBERS},
                "components_lpaeq_dba": dict(zip(names, lpaeq, strict=True)),
                "lw0_per_vehicle_db": {c: r.sound_power[key][c][i].tolist() for c in names},
                "lp_db": out.lp_db[i].tolist(), "lw_db_per_m": out.lw_db[i].tolist(),
                "roughness_db": out.roughness_db[i].tolist()}

    return {"where": r.where, "band_centre_hz": r.model.band_hz.tolist(),
            "definitions": {**METRIC_DEFINITIONS, **SPECTRUM_DEFINITIONS,
                            "roughness_growth_increase_db": f"LpAeq,Tp minus {INCREASE_REFERENCE}"},
            "roughness_growth_increase_reference": f"LpAeq,Tp minus {INCREASE_REFERENCE}", "results": [
        {"model": name, "growth_days": days, "passes": [row((name, days), i) for i in range(len(r.speeds))]}
        for (name, days) in r.results]}
