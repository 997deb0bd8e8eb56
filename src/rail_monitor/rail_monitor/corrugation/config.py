"""The site's corrugation parameters: wavelength bands, K_b per friction state, thresholds, forecast
and advice settings.

K_b defaults follow the order of magnitude of the UQ seminar paper (see
:mod:`rail_monitor.corrugation`): about 1e-5 per pass for dry rail in partial slip (1 nm of
wear per pass at 75 kN with a contact stiffness of 1.3e9 N/m). Wear that drives growth scales
with frictional power, so lubricated states get less: wet about half, a top-of-rail friction
modifier (sold on less corrugation, e.g. Eadie et al., Wear 265 (2008) 1222-1230) and leaf
contamination less still. They are starting values: a pair of roughness surveys re-fits them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.params import ParamSpec, resolve, section, values_of
from rail_monitor.core.passes import FRICTION_NAMES, MAX_SPEED_MPS

SPEED_STEP_MPS = 0.1          # speed grid of the growth tables [m/s]

# K_b per friction state [-/axle pass] (see the module docstring).
K_B_DEFAULTS: dict[str, float] = {"dry": 1.0e-5, "wet": 5.0e-6, "friction_modifier": 3.0e-6, "contaminated": 2.0e-6}

# Also the alert manager's: a grinding-forecast alert stands while the forecast is inside it.
LEAD_TIME = ParamSpec("lead_time_days", 60.0, "Planning lead time: grinding is due when the forecast is inside it "
                      "[day].", 0.0, 3650.0)

CORRUGATION_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("shortest_wavelength_m", 0.01, "Shortest 1/3-octave wavelength band centre tracked [m].", 0.001, 1.0),
    ParamSpec("longest_wavelength_m", 1.0, "Longest 1/3-octave wavelength band centre tracked [m].", 0.01, 10.0),
    ParamSpec("points_per_band", 5, "Wavelengths across each band over which its growth is averaged [-].", 1, 50),
    *(ParamSpec(f"k_b.{state}", value, f"Wear sensitivity K_b with {state} rail, per axle pass [-] (re-fitted "
                "from roughness surveys).", 0.0, 1.0e-2) for state, value in K_B_DEFAULTS.items()),
    ParamSpec("kb_prior_scale_sd", 1.0, "Prior standard deviation of ln K_b common to every friction state [-] "
              "(1: the defaults are known to a factor of e).", 0.01, 10.0),
    ParamSpec("kb_prior_ratio_sd", 0.3, "Prior standard deviation of ln K_b of one friction state about the "
              "common scale [-].", 0.01, 10.0),
    ParamSpec("survey_uncertainty_db", 1.0, "Standard uncertainty of a surveyed band roughness level [dB].",
              0.01, 20.0),
    ParamSpec("post_grinding_uncertainty_db", 3.0, "Standard uncertainty of the post-grinding roughness where a "
              "grinding event gives no spectrum [dB].", 0.01, 20.0),
    ParamSpec("sliding_wear_ratio", 1.0, "Mean wear per pass in full sliding over that in partial slip at the same "
              "friction state [-]; K_b in full sliding is -2/3 of this times K_b (docs/models.md, Sliding).",
              0.0, 100.0),
    ParamSpec("acceptance_factor", 1.0, "Multiplier on the Grassie et al. (1999) post-grinding acceptance limits "
              "[-].", 0.01, 100.0),
    ParamSpec("intervention_factor", 3.0, "Intervention threshold as a multiple of the acceptance limit [-].",
              1.0, 100.0),
    ParamSpec("post_grinding_fraction", 0.5, "Roughness after grinding as a fraction of the acceptance limit, "
              "when the grinding event gives no spectrum [-].", 0.001, 1.0),
    LEAD_TIME,
    ParamSpec("history_days", 28.0, "Passes kept for the forecast (recent speeds, friction, traffic) and for "
              "duplicate detection; older passes are not counted [day].", 0.01, 3650.0),
    ParamSpec("min_traffic_days", 1.0, "Least span of kept passes from which the traffic rate, and so the "
              "forecast in days, is estimated (a shorter span is biased by the daily timetable) [day].", 0.0, 3650.0),
    ParamSpec("advice_min_speed_mps", 0.0, "Lowest speed the advice may use [m/s] (0: the slowest class "
              "minimum of the rolling-stock table).", 0.0, MAX_SPEED_MPS),
    ParamSpec("advice_max_speed_mps", 0.0, "Highest speed the advice may use [m/s] (0: the line speed, the "
              "highest class maximum).", 0.0, MAX_SPEED_MPS),
    ParamSpec("advice_band_kmh", 10.0, "Width of the speed bands the advice publishes per class [km/h] (km/h: "
              "what an operator signs).", 0.5, 50.0),
    ParamSpec("advice_max_share", 0.5, "Largest share of a class's trains the advice puts in one band (raised "
              "to the recent share, or to one over the class's bands, where that is more) [-].", 0.01, 1.0),
    ParamSpec("advice_noise_rise_dba", 0.5, "Most the advice may raise the pass-weighted mean rolling noise "
              "(LpAFmax of each noise model) [dB(A)].", 0.0, 20.0),
    ParamSpec("advice_length_m", 500.0, "Length of track over which the advised speeds hold (the curve with its "
              "approaches): the advice's timetable cost is the running time over it [m].", 1.0, 1.0e5),
)


@dataclass(frozen=True)
class CorrugationConfig:
    """The site's corrugation parameters (names and units as in CORRUGATION_SPECS; k_b.dry is k_b_dry), and
    k_b, the K_b of every friction state."""

    shortest_wavelength_m: float
    longest_wavelength_m: float
    points_per_band: int
    k_b_dry: float
    k_b_wet: float
    k_b_friction_modifier: float
    k_b_contaminated: float
    kb_prior_scale_sd: float
    kb_prior_ratio_sd: float
    survey_uncertainty_db: float
    post_grinding_uncertainty_db: float
    sliding_wear_ratio: float
    acceptance_factor: float
    intervention_factor: float
    post_grinding_fraction: float
    lead_time_days: float
    history_days: float
    min_traffic_days: float
    advice_min_speed_mps: float
    advice_max_speed_mps: float
    advice_band_kmh: float
    advice_max_share: float
    advice_noise_rise_dba: float
    advice_length_m: float

    @property
    def k_b(self) -> np.ndarray:
        """K_b per friction state, index TrainPass.FRICTION_* - 1 [-/axle pass]."""
        return np.array([getattr(self, f"k_b_{name}") for name in FRICTION_NAMES.values()])


def corrugation_config(values: Mapping[str, Any], prefix: str = "corrugation.") -> CorrugationConfig:
    """Checked corrugation parameters from flat parameter values (keys under prefix)."""
    out = resolve(CORRUGATION_SPECS, section(values, prefix), where=prefix, strict=True)
    if out["shortest_wavelength_m"] >= out["longest_wavelength_m"]:
        raise ConfigError(f"parameter '{prefix}shortest_wavelength_m' must be below '{prefix}longest_wavelength_m'")
    if out["min_traffic_days"] > out["history_days"]:
        raise ConfigError(f"parameter '{prefix}min_traffic_days' exceeds '{prefix}history_days'")
    if out["advice_max_speed_mps"] and out["advice_min_speed_mps"] >= out["advice_max_speed_mps"]:
        raise ConfigError(f"parameter '{prefix}advice_min_speed_mps' must be below '{prefix}advice_max_speed_mps'")
    return values_of(CorrugationConfig, out)

