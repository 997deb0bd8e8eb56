"""The site's squeal parameters: the receiver, the friction modifier's reach and the risk thresholds
(the creep curves and k3 are the contact's, rail_monitor.core.site.CONTACT_SPECS; the squealing
wheel mode is each vehicle class's, VEHICLE_SPECS)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from rail_monitor.core.errors import ConfigError
from rail_monitor.core.params import ParamSpec, resolve, section, values_of

# SquealPrediction.RISK_* values.
RISK_NONE, RISK_LOW, RISK_MEDIUM, RISK_HIGH = range(4)

SQUEAL_SPECS: tuple[ParamSpec, ...] = (
    ParamSpec("receiver_distance_m", 7.5, "Distance from the wheel to the receiver [m].", 0.05, 1000.0),
    ParamSpec("spatial_average", 0.5, "Surface-averaged over contact-point squared velocity [-].", 0.0, 1.0),
    ParamSpec("reference_amplitude_mps", 1.0, "A w_ref of the relative level 20 lg(A w / A w_ref) [m/s].",
              1.0e-6, 100.0),
    ParamSpec("friction_modifier_effectiveness", 0.95, "Share of a conditioned train's wheels that meet an "
              "effective friction-modifier film; the rest squeal as on the untreated rail [-] (0.95: a squeal-"
              "dominated pass is 13 dB(A) quieter, near the 12 dB(A) mean reduction of Eadie & Santoro 2006).",
              0.0, 1.0),
    ParamSpec("background_level_dba", 80.0, "Other noise of a pass at the receiver (rolling noise), against "
              "which a friction modifier's benefit is judged [dB(A)].", 0.0, 200.0),
    ParamSpec("risk_medium_dba", 85.0, "Squeal level from which the risk is medium [dB(A)].", 0.0, 200.0),
    ParamSpec("risk_high_dba", 95.0, "Squeal level from which the risk is high [dB(A)].", 0.0, 200.0),
    ParamSpec("fit_days", 7.0, "Windows of measured squeal (from the Unix epoch, UTC) at whose end each friction "
              "state's creep curve is re-fitted from the measured pass-bys and the passes after it predicted on "
              "the posterior's P50 [day]; 0: the configured curves always.", 0.0, 3650.0),
    ParamSpec("fit_window_passes", 2000, "Measured passes per friction state the fit keeps, the newest [-].",
              10, 1_000_000),
    ParamSpec("fit_prior_sd_peak", 0.4, "Prior standard deviation of ln(k1 / the configured k1) [-].", 0.01, 3.0),
    ParamSpec("fit_prior_sd_slope", 0.05, "Prior standard deviation of k2 / k1 about the configured ratio [-].",
              0.001, 1.0),
    ParamSpec("fit_flag_error", 0.05, "The station's squeal flag error: the chance that it flags a pass wrongly, "
              "either way [-]. The fit's likelihood and the predicted share flagged take it; a station better than "
              "this is heard squealing less than predicted on quiet states.", 0.0, 0.45),
)


@dataclass(frozen=True)
class SquealConfig:
    """The site's squeal parameters (names and units as in SQUEAL_SPECS)."""

    receiver_distance_m: float
    spatial_average: float
    reference_amplitude_mps: float
    friction_modifier_effectiveness: float
    background_level_dba: float
    risk_medium_dba: float
    risk_high_dba: float
    fit_days: float
    fit_window_passes: int
    fit_prior_sd_peak: float
    fit_prior_sd_slope: float
    fit_flag_error: float


def squeal_config(values: Mapping[str, Any], prefix: str = "squeal.") -> SquealConfig:
    """Checked squeal parameters from flat parameter values (keys under prefix)."""
    values = resolve(SQUEAL_SPECS, section(values, prefix), where=prefix, strict=True)
    if values["risk_high_dba"] < values["risk_medium_dba"]:
        raise ConfigError(f"parameter '{prefix}risk_high_dba' must not be below '{prefix}risk_medium_dba'")
    return values_of(SquealConfig, values)
